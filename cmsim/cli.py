"""The ``cmsim`` command line: thin argparse wrappers over the library.

Every command accepts ``--json`` and then prints exactly one JSON object on stdout. Errors
in the input print ``cmsim: error: …`` on stderr (and ``{"error": …}`` with ``--json``) and
exit with status 2; a diverged integration exits with status 3.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

from cmsim.errors import IntegrationDiverged, ParameterError

__all__ = ["main", "build_parser"]


def _load_rig(args):
    from cmsim.rig import Rig
    rig = Rig.load(args.rig) if args.rig else Rig.paper_2016()
    if getattr(args, "clearance_m", None) is not None:
        rig = rig.with_clearance(args.clearance_m)
    if getattr(args, "friction", None) is not None:
        if rig.gears is None:
            raise ParameterError("--friction needs a rig with gears")
        rig = rig.with_friction(args.friction)
    return rig


def _operating_point(args):
    from cmsim.rig import OperatingPoint
    return OperatingPoint(speed_rpm=args.speed_rpm, torque_nm=args.torque_nm,
                          radial_load_n=getattr(args, "radial_load_n", 0.0))


def _add_rig_options(p, *, friction=True):
    p.add_argument("--rig", metavar="FILE.toml",
                   help="rig description (default: the paper's rig, Tables 1-3)")
    p.add_argument("--clearance-m", type=float, metavar="C",
                   help="radial clearance of every bearing, m (negative = preload)")
    if friction:
        p.add_argument("--friction", type=float, metavar="F",
                       help="mesh friction coefficient (paper: 0, 0.03, 0.05)")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")


# ---------------------------------------------------------------------- simulate
def _cmd_simulate(args):
    from cmsim.dynamics import SlipModel, simulate
    from cmsim.frequencies import rig_frequencies

    rig = _load_rig(args)
    op = _operating_point(args)
    table, mesh_model = _resolve_mesh_options(args, rig, op.torque_nm)
    slip = SlipModel(cage_speed_rms=args.cage_slip, ball_rms_rad=args.ball_jitter_rad,
                     correlation_s=args.slip_correlation_s)
    run = simulate(rig, op, args.duration_s, fs_hz=args.fs_hz, substeps=args.substeps,
                   mesh=mesh_model if mesh_model is not None else table, slip=slip,
                   seed=args.seed, warmup_s=args.warmup_s)
    if args.out:
        run.save(args.out)
    freqs = rig_frequencies(rig, op)
    first = rig.bearing_names[0]
    out = {"shaft_hz": freqs.fr1_hz, "gmf_hz": freqs.gmf_hz,
           "bpf_hz": freqs.bearing(first).bpf_hz, **run.summary(),
           "out": str(args.out) if args.out else None}
    return out


def _add_mesh_options(p):
    """--mesh, --mesh-table and --table-torque-nm (simulate, modes, sweep)."""
    p.add_argument("--mesh", choices=("hybrid-tables", "potential-energy", "hybrid"),
                   default="hybrid-tables",
                   help="tooth contact: hybrid FE + Weber-Banaschek tables at the run's torque "
                        "(default; paper model B, shipped for the paper's rig, built and "
                        "cached on first use for other rigs), the load-independent "
                        "potential-energy table, or the contact solved on-line from the FE "
                        "influence coefficients (hybrid: paper model A, ~4x slower)")
    p.add_argument("--mesh-table", metavar="FILE.npz",
                   help="pair stiffness table(s) from cmsim mesh-table instead; the table at "
                        "the run's torque is used (linear in torque between tables)")
    p.add_argument("--table-torque-nm", type=float, metavar="T",
                   help="use the --mesh-table table of torque T instead (paper model C: "
                        "tables at the wrong torque)")


def _mesh_argument(args):
    """The ``mesh`` value the options name: a string, or the MeshTableSet / table of a file."""
    if args.table_torque_nm is not None and not args.mesh_table:
        raise ParameterError("--table-torque-nm selects a table of --mesh-table FILE")
    if not args.mesh_table:
        return args.mesh
    if args.mesh != "hybrid-tables":
        raise ParameterError(f"--mesh {args.mesh} and --mesh-table exclude each other")
    from cmsim.mesh_stiffness.table_set import MeshTableSet
    tables = MeshTableSet.load(args.mesh_table)
    return tables if args.table_torque_nm is None else tables.at(args.table_torque_nm)


def _resolve_mesh_options(args, rig, torque_nm):
    """(mesh_table, mesh_model) of the mesh options at ``torque_nm`` (resolve_mesh)."""
    from cmsim.dynamics.mesh_choice import resolve_mesh
    mesh = _mesh_argument(args)
    if rig.gears is None and args.mesh_table:
        raise ParameterError("--mesh-table needs a rig with gears")
    return resolve_mesh(rig, mesh, torque_nm, progress=False if args.json else None)


def _text_simulate(res):
    lines = [f"simulated {res['sim_s']:.3f} s in {res['wall_s']:.3f} s "
             f"(realtime factor {res['realtime_factor']:.1f}, compile {res['compile_s']:.1f} s)",
             f"shaft {res['shaft_hz']:.3f} Hz, ball pass {res['bpf_hz']:.3f} Hz"]
    if res["gmf_hz"] is not None:
        lines.append(f"GMF {res['gmf_hz']:.2f} Hz; DTE mean {res['dte_mean_um']:.3f} um, "
                     f"rms {res['dte_rms_um']:.3f} um (mean {res['dte_mean_rad']:.3e} rad)")
    if res["out"]:
        lines.append(f"wrote {res['out']} (seed {res['seed']})")
    return "\n".join(lines)


def _add_simulate(sub):
    p = sub.add_parser("simulate", help="simulate the rig at one operating point",
                       description="Integrate the model and write a run (.npz).")
    p.add_argument("--speed-rpm", type=float, required=True, help="input shaft speed, rpm")
    p.add_argument("--torque-nm", type=float, default=0.0, help="output torque, N m")
    p.add_argument("--radial-load-n", type=float, default=0.0,
                   help="static radial load on shaft 1's centre node, N (bearing rigs)")
    p.add_argument("--duration-s", type=float, default=0.5, help="recorded duration, s")
    p.add_argument("--fs-hz", type=float, default=75_000.0,
                   help="output sample rate, Hz (any acquisition rate: the integration step "
                        "follows the model, and the record is anti-alias filtered)")
    p.add_argument("--substeps", type=int, default=None,
                   help="integration steps per output sample (default: the fewest giving "
                        ">= 4.7 steps per period of the highest mode; 1 at 75 kHz on the "
                        "paper rig, 3 at 25.6 kHz)")
    p.add_argument("--warmup-s", type=float, default=0.05, help="discarded start, s")
    _add_mesh_options(p)
    p.add_argument("--cage-slip", type=float, default=0.0, metavar="FRACTION",
                   help="rms random cage-speed fluctuation (0.01 = 1 %%); spreads ball-pass lines")
    p.add_argument("--ball-jitter-rad", type=float, default=0.0,
                   help="rms random angular deviation of each ball in its pocket, rad")
    p.add_argument("--slip-correlation-s", type=float, default=5e-3,
                   help="correlation time of the slip processes, s")
    p.add_argument("--seed", type=int, help="random seed (recorded in the run)")
    p.add_argument("--out", type=Path, metavar="RUN.npz", help="write the run here")
    _add_rig_options(p)
    p.set_defaults(func=_cmd_simulate, text=_text_simulate)


# ---------------------------------------------------------------------- modes
def _cmd_modes(args):
    from cmsim.dynamics.modal import modal_analysis
    rig = _load_rig(args)
    op = _operating_point(args)
    table, mesh_model = _resolve_mesh_options(args, rig, op.torque_nm)
    res = modal_analysis(rig, op, mesh_model if mesh_model is not None else table,
                         n_positions=args.positions)
    return {"torque_nm": args.torque_nm, "speed_rpm": args.speed_rpm,
            "frequencies_hz": [float(f) for f in res.frequencies_hz],
            "types": list(res.types), "details": list(res.details),
            "rotational_share": [float(x) for x in res.rotational_share],
            "mean_mesh_stiffness_n_per_m": res.mean_mesh_stiffness_n_per_m}


def _text_modes(res):
    lines = [f"natural frequencies at {res['torque_nm']:g} N m",
             " mode  frequency_hz  type  detail"]
    for i, (f, t, d) in enumerate(zip(res["frequencies_hz"], res["types"], res["details"])):
        lines.append(f" {i + 1:4d}  {f:12.1f}  {t:4s}  {d}")
    return "\n".join(lines)


def _add_modes(sub):
    p = sub.add_parser("modes", help="natural frequencies of the linearised model",
                       description="Linearise about the quasi-static state (bearings averaged "
                                   "over a ball-pass cycle) and solve the eigenproblem.")
    p.add_argument("--torque-nm", type=float, required=True, help="output torque, N m")
    p.add_argument("--speed-rpm", type=float, default=1000.0,
                   help="speed, rpm (sets the bearing-cycle instants)")
    p.add_argument("--positions", type=int, default=24,
                   help="quasi-static positions averaged over a bearing cycle")
    _add_mesh_options(p)
    _add_rig_options(p, friction=False)
    p.set_defaults(func=_cmd_modes, text=_text_modes)


# ---------------------------------------------------------------------- spectrum
def _save_figure(fig, path):
    import io

    from cmsim._io import atomic_write_bytes
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    atomic_write_bytes(path, buf.getvalue())


def _cmd_spectrum(args):
    from cmsim.run import Run
    from cmsim.spectra.run_spectrum import run_spectrum

    run = Run.load(args.run)
    spec = run_spectrum(run, args.signal, args.kind, band_hz=args.band_hz, max_hz=args.max_hz,
                        resolution_hz=args.resolution_hz, bearing=args.bearing,
                        max_peaks=args.top, threshold_db=args.threshold_db)
    out = {"run": str(args.run), "signal": spec.signal, "kind": spec.kind, "unit": spec.unit,
           "resolution_hz": spec.resolution_hz, "bearing": spec.bearing,
           "families": spec.families, "band_hz": list(spec.band_hz) if spec.band_hz else None,
           "max_hz": spec.max_hz, "n_peaks": len(spec.peaks), "peaks": spec.peak_records(),
           "plot": None, **spec.extra}
    if args.plot:
        from cmsim.spectra.plots import plot_spectrum
        fam = spec.families
        fig = plot_spectrum(spec.freq_hz, spec.amplitude, spec.peaks, fam,
                            amplitude_unit=spec.unit, max_freq=spec.max_hz,
                            max_harmonic=max(1, int(spec.max_hz // fam.get("GMF", spec.max_hz))),
                            title=f"{spec.signal}: {spec.kind} spectrum "
                                  f"({spec.resolution_hz:.3g} Hz resolution)")
        _save_figure(fig, args.plot)
        out["plot"] = str(args.plot)
    return out


def _text_spectrum(res):
    lines = [f"{res['kind']} spectrum of {res['signal']} [{res['unit']}], resolution "
             f"{res['resolution_hz']:.4g} Hz, families of bearing {res['bearing']}: "
             + ", ".join(f"{k} {v:.3f} Hz" for k, v in res["families"].items())]
    if res["band_hz"]:
        lines.append(f"demodulation band {res['band_hz'][0]:.0f}-{res['band_hz'][1]:.0f} Hz")
    lines.append(f"{'frequency_hz':>13}  {'amplitude':>11}  {'dB re carrier':>13}  label")
    for p in res["peaks"]:
        db = "" if p["db_re_carrier"] is None else f"{p['db_re_carrier']:.1f}"
        lines.append(f"{p['frequency_hz']:13.2f}  {p['amplitude']:11.4g}  {db:>13}  "
                     f"{p['label']}")
    if res["plot"]:
        lines.append(f"wrote {res['plot']}")
    return "\n".join(lines)


def _add_spectrum(sub):
    p = sub.add_parser("spectrum", help="labelled spectrum of one signal of a run",
                       description="Amplitude, envelope or order spectrum of a run signal, "
                                   "with its largest peaks named k·GMF ± m·BPF ± n·fr from "
                                   "the run's own rig and operating point.")
    p.add_argument("run", type=Path, metavar="RUN.npz", help="run written by cmsim simulate")
    p.add_argument("--signal", default="F_1b1_loa", help="signal name (default F_1b1_loa)")
    p.add_argument("--kind", default="amplitude", choices=("amplitude", "envelope", "order"),
                   help="spectrum kind")
    p.add_argument("--band-hz", type=float, nargs=2, metavar=("LO", "HI"),
                   help="demodulation band for --kind envelope, Hz (default: kurtogram's)")
    p.add_argument("--max-hz", type=float, metavar="F", help="list peaks up to F Hz")
    p.add_argument("--resolution-hz", type=float, metavar="R",
                   help="required bin spacing, Hz (error if the record is too short)")
    p.add_argument("--bearing", help="bearing for the BPF family (default: from the signal)")
    p.add_argument("--top", type=int, default=20, help="number of largest peaks listed")
    p.add_argument("--threshold-db", type=float, default=15.0,
                   help="least peak height above the noise floor, dB")
    p.add_argument("--plot", type=Path, metavar="OUT.png", help="write the spectrum figure")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=_cmd_spectrum, text=_text_spectrum)


# ---------------------------------------------------------------------- sweep
def _cmd_sweep(args):
    from cmsim.datasets import SweepSpec, run_sweep
    from cmsim.rig import Rig

    rig = Rig.load(args.rig) if args.rig else Rig.paper_2016()
    mesh = _mesh_argument(args)
    if mesh == "hybrid-tables" and rig.gears is not None:
        # build (or load) the rig's tables once, before the workers start
        from cmsim.dynamics.mesh_choice import hybrid_table_set
        hybrid_table_set(rig, progress=False if args.json else None)
    spec = SweepSpec(speeds_rpm=args.speed_rpm, torques_nm=args.torque_nm,
                     duration_s=args.duration_s, frictions=args.friction or (None,),
                     clearances_m=args.clearance_m or (None,), rig=rig, fs_hz=args.fs_hz,
                     warmup_s=args.warmup_s, substeps=args.substeps, seed=args.seed,
                     seed_policy=args.seed_policy, mesh=mesh)
    progress = not args.json and sys.stderr.isatty()
    try:
        summary = run_sweep(spec, args.out, workers=args.workers, force=args.force,
                            progress=progress)
    except KeyboardInterrupt:
        msg = (f"interrupted; finished runs are kept in {args.out}/manifest.json, re-run the "
               f"same command to resume")
        print(f"cmsim: {msg}", file=sys.stderr)
        if args.json:
            print(json.dumps({"error": msg}))
        raise SystemExit(130) from None
    return summary.to_dict()


def _text_sweep(res):
    lines = [f"{res['n_runs']} runs in {res['dir']}: {res['completed']} simulated, "
             f"{res['skipped']} already there ({res['adopted']} adopted), "
             f"{len(res['failed'])} failed",
             f"wall {res['wall_s']:.2f} s on {res['workers']} workers ({res['start_method']}); "
             f"integration {res['integration_s']:.2f} s, compile {res['compile_s']:.2f} s, "
             f"setup {res['setup_s']:.2f} s, spectra {res['spectra_s']:.2f} s, "
             f"save {res['save_s']:.2f} s; utilisation {100 * res['utilisation']:.0f} %",
             f"manifest {res['manifest']}"]
    return "\n".join(lines)


def _add_sweep(sub):
    p = sub.add_parser("sweep", help="simulate a grid of operating points in parallel",
                       description="Simulate speeds × torques (× frictions × clearances) on "
                                   "worker processes; each run is saved to DIR/runs/ and "
                                   "recorded in DIR/manifest.json as it finishes. Re-running "
                                   "the same command resumes: finished runs are skipped.")
    p.add_argument("--torque-nm", type=float, nargs="+", required=True,
                   help="output torques, N m")
    p.add_argument("--speed-rpm", type=float, nargs="+", required=True,
                   help="input shaft speeds, rpm")
    p.add_argument("--duration-s", type=float, default=1.0, help="recorded duration, s")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="sweep directory")
    p.add_argument("--rig", metavar="FILE.toml",
                   help="rig description (default: the paper's rig, Tables 1-3)")
    p.add_argument("--friction", type=float, nargs="+", metavar="F",
                   help="mesh friction coefficients (default: the rig's)")
    p.add_argument("--clearance-m", type=float, nargs="+", metavar="C",
                   help="bearing radial clearances, m (negative = preload; default: the "
                        "rig's)")
    p.add_argument("--fs-hz", type=float, default=75_000.0, help="output sample rate, Hz")
    p.add_argument("--warmup-s", type=float, default=0.05, help="discarded start, s")
    p.add_argument("--substeps", type=int, default=1, help="integration steps per sample")
    p.add_argument("--seed", type=int, default=0,
                   help="base seed; run i gets a seed derived from (seed, i)")
    p.add_argument("--seed-policy", default="per_run", choices=("per_run", "shared"),
                   help="per_run: independent seed per run; shared: every run uses --seed")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes (default: number of CPUs)")
    p.add_argument("--force", action="store_true",
                   help="replace a manifest written for a different spec")
    _add_mesh_options(p)
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=_cmd_sweep, text=_text_sweep)


# ---------------------------------------------------------------------- report
def _cmd_report(args):
    from cmsim.report import DEFAULT_SIGNALS, build_report

    res = build_report(args.dir, tuple(args.signal) if args.signal else DEFAULT_SIGNALS,
                       top_n=args.top, max_freq_hz=args.max_hz,
                       progress=not args.json and sys.stderr.isatty())
    return res.to_dict()


def _text_report(res):
    lines = [f"wrote {res['html']} with {len(res['figures'])} figures "
             f"({', '.join(res['figures'])})",
             f"report {res['total_s']:.2f} s: load {res['load_s']:.2f} s, spectra "
             f"{res['spectra_s']:.2f} s, plots {res['plot_s']:.2f} s, html {res['write_s']:.2f} s"]
    if res["dominant_signal"]:
        lines.append(f"dominant GMF harmonic of {res['dominant_signal']}: " + ", ".join(
            f"{r['name']}: {r['dominant_gmf_harmonic']}" for r in res["runs"]))
    return "\n".join(lines)


def _add_report(sub):
    p = sub.add_parser("report", help="HTML report (waterfalls, orbits, DTE) of a sweep",
                       description="Write DIR/report.html and its PNG figures from the run "
                                   "files of a sweep directory.")
    p.add_argument("dir", type=Path, metavar="DIR", help="sweep directory (cmsim sweep --out)")
    p.add_argument("--signal", nargs="+", metavar="NAME",
                   help="signals drawn as waterfalls (default: dte_um F_1b1_loa F_1b1_oloa)")
    p.add_argument("--top", type=int, default=8, help="labelled peaks listed per run")
    p.add_argument("--max-hz", type=float, metavar="F",
                   help="upper frequency of the waterfalls, Hz (default 6.5 GMF)")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=_cmd_report, text=_text_report)


# ---------------------------------------------------------------------- main
def build_parser():
    """The argparse parser of ``cmsim``."""
    parser = argparse.ArgumentParser(
        prog="cmsim", description="Vibration of a spur-gear transmission on ball bearings "
                                  "(19-DOF model of Fernandez-del-Rincon et al. 2016).")
    from cmsim import __version__
    parser.add_argument("--version", action="version", version=f"cmsim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for add in _COMMANDS:
        add(sub)
    return parser


# ---------------------------------------------------------------------- mesh-table
def _cmd_mesh_table(args):
    import time

    from cmsim.dynamics.torque_tables import torque_tables

    rig = _load_rig(args)
    if rig.gears is None:
        raise ParameterError("cmsim mesh-table needs a rig with gears")
    start = time.perf_counter()
    mesh_model = None
    cache = None
    if args.method == "hybrid":
        from cmsim.mesh_stiffness.hybrid import HybridMeshModel
        mesh_model = HybridMeshModel.from_pair(rig.gears)
        info = mesh_model.driving.meta
        cache = {"status": info.get("cache"), "key": info.get("key"),
                 "build_s": info.get("build_seconds"),
                 "load_s": time.perf_counter() - start}

    def progress(i, n, row):
        if not args.json and sys.stderr.isatty():
            print(f"  {i}/{n}: {row['torque_nm']:g} N m", file=sys.stderr)

    tables = torque_tables(rig, args.torque_nm, args.method, mesh_model=mesh_model,
                           speed_rpm=args.speed_rpm, n_steps=args.steps,
                           centres=args.centres, progress=progress)
    if args.out:
        tables.save(args.out)
    return {"method": args.method, "rig": rig.name, "centres": args.centres,
            "tables": list(tables.summary), "influence_cache": cache,
            "seconds": time.perf_counter() - start, "out": str(args.out) if args.out else None}


def _text_mesh_table(res):
    lines = [f"{res['method']} mesh stiffness of {res['rig']} ({res['seconds']:.1f} s)",
             f"{'torque_nm':>10}  {'mean_k_N/m':>11}  {'p2p_k_N/m':>11}  {'contact_ratio':>13}"]
    for row in res["tables"]:
        lines.append(f"{row['torque_nm']:10g}  {row['mean_stiffness_n_per_m']:11.4g}  "
                     f"{row['peak_to_peak_stiffness_n_per_m']:11.4g}  "
                     f"{row['loaded_contact_ratio']:13.3f}")
    if res["out"]:
        lines.append(f"wrote {res['out']}")
    return "\n".join(lines)


def _add_mesh_table(sub):
    p = sub.add_parser("mesh-table", help="torque-dependent pair stiffness tables",
                       description="Pair stiffness vs position on the line of action for "
                                   "each torque (paper 001 section 6.1): quasi-static orbits "
                                   "over a bearing cycle, their centroids, then one mesh cycle "
                                   "with the gear centres there.")
    p.add_argument("--torque-nm", type=float, nargs="+", required=True,
                   help="output torques, N m")
    p.add_argument("--method", choices=("hybrid", "potential-energy"), default="hybrid",
                   help="hybrid FE + Weber-Banaschek (default) or potential energy")
    p.add_argument("--centres", choices=("centroid", "nominal"), default="centroid",
                   help="gear centres of the mesh-cycle sweep (default: orbit centroids)")
    p.add_argument("--speed-rpm", type=float, default=1000.0,
                   help="speed of the quasi-static orbits, rpm")
    p.add_argument("--steps", type=int, default=120,
                   help="driving-gear angles per mesh cycle")
    p.add_argument("--out", type=Path, metavar="TABLE.npz",
                   help="write the tables (for cmsim simulate --mesh-table)")
    _add_rig_options(p, friction=False)
    p.set_defaults(func=_cmd_mesh_table, text=_text_mesh_table)


_COMMANDS = [_add_simulate, _add_modes, _add_mesh_table, _add_spectrum, _add_sweep,
             _add_report]


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


_NEGATIVE_EXPONENT_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)e[-+]?\d+$", re.IGNORECASE)


def _plain_negative_numbers(argv):
    """``-1e-6`` → ``-0.000001``: argparse takes a negative number in exponent notation for an
    option, but a plain decimal for a value, also in lists (``--clearance-m 0 -1e-6``)."""
    return [np.format_float_positional(float(a), trim="-")
            if _NEGATIVE_EXPONENT_NUMBER.match(a) else a for a in argv]


def main(argv=None):
    """Entry point of the ``cmsim`` console script; returns the exit status."""
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(_plain_negative_numbers(argv))
    try:
        res = args.func(args)
    except (ParameterError, FileNotFoundError) as exc:
        return _fail(args, str(exc), 2)
    except IntegrationDiverged as exc:
        return _fail(args, str(exc), 3)
    if args.json:
        print(json.dumps(_jsonable(res)))
    else:
        print(args.text(res))
    return 0


def _fail(args, message, status):
    print(f"cmsim: error: {message}", file=sys.stderr)
    if getattr(args, "json", False):
        print(json.dumps({"error": message}))
    return status


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
