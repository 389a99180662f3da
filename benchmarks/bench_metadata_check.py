"""The metadata-vs-signal check measured both ways (issue 48): how many honest records it
refuses (must be 0) and how many doctored ones it catches.

Run: ``python benchmarks/bench_metadata_check.py [--data DIR] [--skip exports] [--json FILE]``
(``--data`` defaults to ``$CMSIM_DATA`` or ``../shared/datasets``). Nothing is written into
``--data``: every copy, cut and export lives in a temporary folder.

Honest records (a refusal is a false refusal; a warning is counted but allowed):

* ``shared`` — every recording of the shared datasets as it is;
* ``cut 5 s`` — its first, middle and last 5 s (records of at least 5 s; MFPT's are 3 s),
  written as a copy with its metadata entry;
* ``export`` — cmsim's own files: every preset rig (healthy and with each fault type its
  geometry takes) simulated with ``--sensors --sensor-fs-hz 25600``, exported with ``cmsim
  export --format npz|csv|wav|mat|uff|tdms`` and read back by ``cmsim spectrum`` (the whole
  command line, in this process).

Doctored records (caught = refused; a warning is counted apart):

* ``fs x2``, ``fs x1/2``, ``fs x4``, ``fs x1/4`` — the stated sample rate made wrong by that
  factor in a copy of each shared record's metadata (the gearbox's, which states none, gets
  the factor times the rate inferred from its mesh);
* ``speed x2``, ``speed x1/2`` — every documented speed key made wrong (the gearbox's copy
  states the inferred rate as well: with an undocumented rate, inferred from the speed, a
  wrong speed moves the rate with it and nothing in the signal can tell);
* ``48 kHz label`` — the CWRU outer-race record labelled 48 kHz (issue 26's case).

Each case is read by :func:`cmsim.measured.read_record`, the reader behind every command.
"""

import argparse
import json
import shutil
import sys
import tempfile
import time
import warnings
from contextlib import redirect_stderr, redirect_stdout
from io import StringIO
from pathlib import Path

import numpy as np

from cmsim.cli import main
from cmsim.errors import ParameterError
from cmsim.measured import data_root, read_record
from cmsim.rig import preset

#: Doctored classes: (name, key, factor).
DOCTORED = (("fs x2", "fs", 2.0), ("fs x1/2", "fs", 0.5), ("fs x4", "fs", 4.0),
            ("fs x1/4", "fs", 0.25), ("speed x2", "speed", 2.0),
            ("speed x1/2", "speed", 0.5))

#: Speed keys of a recording entry and their unit factor (all are scaled together).
SPEED_KEYS = ("shaft_speed_rpm", "shaft_speed_hz", "shaft_speed_rpm_nominal",
              "shaft_speed_hz_nominal")

#: Length of a cut, s.
CUT_S = 5.0

#: Operating point of each preset rig's exports.
PRESET_OPS = {"paper_2016": ["--speed-rpm", "1000", "--torque-nm", "100"],
              "cwru_6205": ["--speed-rpm", "1797", "--radial-load-n", "1000"],
              "mfpt_nice": ["--speed-rpm", "1500", "--radial-load-n", "1200"]}

#: One fault of each type (bearing faults on the first bearing, gear faults on gear 1).
FAULTS = {
    "healthy": None,
    "outer_race": "outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4",
    "inner_race": "inner_race:bearing=1b1,size_m=1e-3,depth_m=1e-4",
    "ball": "ball:bearing=1b1,size_m=1e-3,depth_m=1e-4",
    "wear": "wear:bearing=1b1,clearance_growth_m=1e-5",
    "off_size_ball": "off_size_ball:bearing=1b1,diameter_excess_m=2e-6",
    "rolling_slip": "rolling_slip:cage_speed_rms=0.01",
    "eccentricity": "eccentricity:gear=1,amplitude_m=2e-5",
    "tooth_crack": "tooth_crack:gear=1,depth_m=1e-3",
    "tooth_spall": "tooth_spall:gear=1,width_m=1e-3,depth_m=2e-5",
    "tooth_breakage": "tooth_breakage:gear=1,lost_height_m=1e-3",
    "profile_error": "profile_error:gear=1,wear_depth_m=5e-6",
    "speed_fluctuation": "speed_fluctuation:relative_amplitude=0.01,frequency_hz=3",
    "torque_ripple": "torque_ripple:relative_amplitude=0.1,order=2",
}

FORMATS = ("npz", "csv", "wav", "mat", "uff", "tdms")


def _outcome(path, **kwargs):
    """``("refused" | "warned" | "passed" | "error", text)`` of reading one record."""
    try:
        rec = read_record(path, **kwargs)
    except ParameterError as exc:
        text = " ".join(str(exc).split())
        return ("refused" if "would fit" in text else "error"), text
    warnings = [w for w in rec.meta.get("warnings") or [] if "sample rate" in w]
    if warnings:
        return "warned", warnings[0]
    return "passed", ""


def _copy(tmp, folder, file, signals=None, entry_changes=None, folder_changes=None):
    """A copy of one shared record (its signals replaced by ``signals``) in its own folder
    under ``tmp`` with its metadata changed; the path of the copied file."""
    d = Path(tempfile.mkdtemp(dir=tmp))
    meta = json.loads((folder / "metadata.json").read_text())
    entry = next(r for r in meta["recordings"] if r["file"] == file)
    meta["recordings"] = [entry]
    entry.update(entry_changes or {})
    meta.update(folder_changes or {})
    if signals is None:
        shutil.copy(folder / file, d / file)
    else:
        np.savez_compressed(d / file, **signals)
        entry["n_samples"] = int(next(iter(signals.values())).size)
    (d / "metadata.json").write_text(json.dumps(meta))
    return d / file


def _shared_records(data):
    out = []
    for folder in sorted(p for p in data.iterdir() if (p / "metadata.json").is_file()):
        meta = json.loads((folder / "metadata.json").read_text())
        out += [(folder, r["file"]) for r in meta["recordings"]]
    return out


def honest_shared(data, tmp, rows):
    """Every shared record and its 5-s cuts."""
    for folder, file in _shared_records(data):
        name = f"{folder.name}/{file}"
        rows.append(("shared", name, *_outcome(folder / file)))
        z = np.load(folder / file)
        signals = {k: z[k] for k in z.files}
        n = next(iter(signals.values())).size
        try:
            fs = read_record(folder / file).fs_hz
        except ParameterError:
            continue
        m = int(round(CUT_S * fs))
        if m >= n:
            continue
        for where, a in (("first", 0), ("middle", (n - m) // 2), ("last", n - m)):
            cut = {k: v[a:a + m] for k, v in signals.items()}
            p = _copy(tmp, folder, file, cut, {"segment": f"{where} {CUT_S:g} s"})
            rows.append(("cut 5 s", f"{name} {where}", *_outcome(p)))


def doctored(data, tmp, rows):
    """Every shared record with a wrong rate or speed, and the 48-kHz label."""
    for folder, file in _shared_records(data):
        meta = json.loads((folder / "metadata.json").read_text())
        entry = next(r for r in meta["recordings"] if r["file"] == file)
        rec = read_record(folder / file)
        fs = rec.fs_hz
        for label, key, factor in DOCTORED:
            if key == "fs":
                changes, top = {"fs_hz": fs * factor}, {"fs_hz": fs * factor}
            else:
                changes = {k: entry[k] * factor for k in SPEED_KEYS
                           if entry.get(k) is not None}
                top = {}
                if meta.get("fs_hz") is None:           # state the inferred rate
                    changes["fs_hz"], top = fs, {"fs_hz": fs}
            p = _copy(tmp, folder, file, None, changes, top)
            rows.append((label, f"{folder.name}/{file}", *_outcome(p)))
    cwru = data / "cwru_bearing_12k_de"
    if (cwru / "OR007_at6_0.npz").is_file():
        p = _copy(tmp, cwru, "OR007_at6_0.npz", None, {"fs_hz": 48000.0},
                  {"fs_hz": 48000.0})
        rows.append(("48 kHz label", "cwru_bearing_12k_de/OR007_at6_0.npz", *_outcome(p)))


def _cli(argv):
    """``(status, JSON object)`` of one command line run in this process."""
    out, err = StringIO(), StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        status = main(argv + ["--json"])
    text = out.getvalue().strip().splitlines()
    return status, (json.loads(text[-1]) if text else {})


def honest_exports(tmp, rows, duration_s):
    """cmsim's own exports of every preset with every fault type, read by spectrum."""
    for rig, op in PRESET_OPS.items():
        for fault, spec in FAULTS.items():
            run = tmp / f"{rig}_{fault}.npz"
            argv = ["simulate", *op, "--sensors", "--sensor-fs-hz", "25600",
                    "--duration-s", str(duration_s), "--out", str(run)]
            if rig != "paper_2016":                  # the default rig needs no file
                if not (tmp / f"{rig}.toml").is_file():
                    preset(rig).save(tmp / f"{rig}.toml")
                argv += ["--rig", str(tmp / f"{rig}.toml")]
            if spec:
                argv += ["--fault", spec]
            status, res = _cli(argv)
            if status != 0:          # the fault does not fit this rig (a gear fault on a
                continue             # bearing rig): not a record
            for fmt in FORMATS:
                out = tmp / f"{rig}_{fault}_{fmt}"
                status, res = _cli(["export", str(run), "--format", fmt, "--out", str(out)])
                if status != 0:
                    rows.append(("export", f"{rig} {fault} {fmt}", "error",
                                 res.get("error", "")))
                    continue
                status, res = _cli(["spectrum", str(out / f"{run.stem}.{fmt}")])
                if status != 0:
                    text = res.get("error", "")
                    kind = "refused" if "would fit" in text else "error"
                    rows.append(("export", f"{rig} {fault} {fmt}", kind, text))
                    continue
                warned = [w for w in res.get("warnings", []) if "sample rate" in w]
                rows.append(("export", f"{rig} {fault} {fmt}",
                             "warned" if warned else "passed", warned[0] if warned else ""))


def table(rows):
    """The counts per class, as a Markdown table."""
    classes = list(dict.fromkeys(r[0] for r in rows))
    lines = ["| class | records | refused | warned | passed | other error |",
             "|---|---|---|---|---|---|"]
    for c in classes:
        sel = [r for r in rows if r[0] == c]
        n = {k: sum(r[2] == k for r in sel) for k in ("refused", "warned", "passed",
                                                        "error")}
        lines.append(f"| {c} | {len(sel)} | {n['refused']} | {n['warned']} | {n['passed']} | "
                     f"{n['error']} |")
    honest = [r for r in rows if r[0] in ("shared", "cut 5 s", "export")]
    bad = [r for r in rows if r not in honest]
    lines += ["", f"honest refused: {sum(r[2] in ('refused', 'error') for r in honest)} of "
              f"{len(honest)} (warned {sum(r[2] == 'warned' for r in honest)})",
              f"doctored caught: {sum(r[2] == 'refused' for r in bad)} of {len(bad)} "
              f"(warned {sum(r[2] == 'warned' for r in bad)})"]
    return "\n".join(lines)


def run(argv=None):
    """Measure and print the table; the rows and the table as a dict."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", type=Path, default=data_root())
    p.add_argument("--skip", nargs="*", default=(), choices=("shared", "doctored", "exports"))
    p.add_argument("--duration-s", type=float, default=2.0,
                   help="duration of each simulated export, s")
    p.add_argument("--json", type=Path, help="write the rows and counts here")
    p.add_argument("--verbose", action="store_true", help="print every refusal and warning")
    args = p.parse_args(argv)
    warnings.simplefilter("ignore")     # a record's warnings are counted from its meta
    rows = []
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="cmsim-bench-check-") as tmp:
        tmp = Path(tmp)
        if "shared" not in args.skip:
            honest_shared(args.data, tmp, rows)
        if "exports" not in args.skip:
            honest_exports(tmp, rows, args.duration_s)
        if "doctored" not in args.skip:
            doctored(args.data, tmp, rows)
    text = table(rows)
    print(text)
    print(f"({time.perf_counter() - t0:.0f} s)")
    honest = ("shared", "cut 5 s", "export")
    for r in rows:
        if args.verbose and ((r[0] in honest and r[2] != "passed")
                             or (r[0] not in honest and r[2] != "refused")):
            print(f"  {r[0]}: {r[1]}: {r[2]} {r[3][:300]}", file=sys.stderr)
    if args.json:
        args.json.write_text(json.dumps({"rows": rows, "table": text}, indent=1))
    return {"rows": rows, "table": text}


if __name__ == "__main__":
    run()
