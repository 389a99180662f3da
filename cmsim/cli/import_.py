"""``cmsim import``: a folder of recordings documented as ``metadata.json`` (what the files
state, the rest from the options), so compare, calibrate, spectrum and evaluate read it."""

from __future__ import annotations

import json
from pathlib import Path

from cmsim.cli.contract import CLIError
from cmsim.cli.options import add_recording_options, recording_values
from cmsim.errors import ParameterError


def register(sub):
    """Add the ``import`` parser."""
    p = sub.add_parser("import", help="write metadata.json for a folder of recordings",
                       description="Read every recording of DIR (.npz, .csv, .wav, .mat, "
                                   ".uff/.unv, .tdms) and write the metadata.json cmsim "
                                   "reads: channel names, sample rate, units and speed as "
                                   "the files state them, then what a metadata.json already "
                                   "in DIR states, the rest from --fs-hz, --speed-rpm, "
                                   "--unit, --calibration and --channel (two sources that "
                                   "disagree are refused). Geometry and the answer key are "
                                   "not in any file: add them by hand; --force keeps them "
                                   "(and every key import does not write). Runs and dataset "
                                   "records cmsim wrote (.npz with a meta array) need no "
                                   "metadata: they are left out, with a warning.")
    p.add_argument("dir", type=Path, metavar="DIR", help="folder of recordings")
    p.add_argument("--out", type=Path, metavar="FILE.json",
                   help="metadata file to write (default DIR/metadata.json, where compare "
                        "and the others look for it)")
    p.add_argument("--force", action="store_true",
                   help="rewrite an existing --out file: the values import produces are "
                        "replaced, every other key (geometry, sensor positions, a "
                        "recording's condition or answer key) is kept")
    p.add_argument("--channel", nargs="+", metavar="NAME",
                   help="names of a file's unnamed channels (a WAV's, in order), or the "
                        "channels to document of files that name theirs")
    add_recording_options(p, trust=False)       # import reads no lines: nothing to trust
    p.set_defaults(func=run, text=text)


def run(args):
    """Read the folder, write its metadata."""
    from cmsim.measured.importing import folder_metadata, write_folder_metadata

    out = args.out or args.dir / "metadata.json"
    if args.channel and len(set(args.channel)) < len(args.channel):
        raise CLIError(f"--channel must not repeat a name, got {' '.join(args.channel)}: a "
                       f"channel documented twice could never be told from its namesake",
                       option="--channel")
    if out.exists() and not args.force:
        raise CLIError(f"--out {out}: exists; give --force to overwrite it"
                       + ("" if args.out else " (or --out FILE.json: this is its default, "
                          "DIR/metadata.json)"), option="--out")
    values = recording_values(args)
    values.pop("trust_metadata")
    keep = None
    if out.exists():                               # --force: keep what import does not write
        try:
            keep = json.loads(out.read_text())
        except (ValueError, OSError) as exc:
            raise CLIError(f"--out {out}: not valid JSON ({' '.join(str(exc).split())}); "
                           f"repair or remove it", option="--out") from None
    try:
        meta, undocumented, skipped, unreadable = folder_metadata(
            args.dir, channels=args.channel, keep=keep, **values)
    except ParameterError as exc:
        if exc.param not in ("record", "dataset"):
            raise
        raise CLIError(f"DIR {' '.join(str(exc).split())}", option="DIR") from None
    write_folder_metadata(out, meta, force=True)
    if skipped:
        args.warn(f"left out {', '.join(skipped)}: written by cmsim (a run or dataset "
                  f"record), they state their own rate, speed and rig and need no metadata")
    for name, why in unreadable:
        args.warn(f"left out {name}: {why}")
    for what in undocumented:
        option = next((o for k, o in _OPTION_OF.items() if k in what), "an option")
        args.warn(f"{what} undocumented (give {option}, or edit {out.name})")
    recs = meta["recordings"]
    return {"metadata": str(out), "dir": str(args.dir), "n_recordings": len(recs),
            "fs_hz": meta["fs_hz"], "channels": sorted(meta["channels"]),
            "units": {c: s["unit"] for c, s in meta["sensors"].items()},
            "recordings": [{k: r.get(k) for k in ("file", "n_samples", "fs_hz",
                                                  "shaft_speed_rpm", "channels")}
                           for r in recs],
            "undocumented": list(undocumented), "skipped": list(skipped),
            "unreadable": dict(unreadable)}


#: What import reports undocumented → the option that gives it.
_OPTION_OF = {"sample rate": "--fs-hz", "shaft speed": "--speed-rpm", "unit of": "--unit"}


def text(res):
    """One line per recording and where the metadata went."""
    lines = [f"{r['file']}: {r['n_samples']} samples"
             + (f" at {r['fs_hz']:g} Hz" if r["fs_hz"] else ", rate undocumented")
             + (f", {r['shaft_speed_rpm']:g} rpm" if r["shaft_speed_rpm"] else "")
             + f"; channels {', '.join(r['channels'])}" for r in res["recordings"]]
    lines.append(f"wrote {res['metadata']} ({res['n_recordings']} recordings; add geometry "
                 f"and the answer key by hand)")
    return "\n".join(lines)
