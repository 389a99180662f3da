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
    rig = _load_file("--rig", args.rig, Rig.load, "a rig TOML file") if args.rig \
        else Rig.paper_2016()
    if getattr(args, "clearance_m", None) is not None:
        rig = rig.with_clearance(args.clearance_m)
    if getattr(args, "friction", None) is not None:
        if rig.gears is None:
            raise CLIError("--friction needs a rig with gears", option="--friction")
        rig = rig.with_friction(args.friction)
    return rig


def _operating_point(args, rig=None):
    from cmsim.rig import OperatingPoint
    op = OperatingPoint(speed_rpm=args.speed_rpm, torque_nm=args.torque_nm,
                        radial_load_n=getattr(args, "radial_load_n", 0.0))
    if rig is not None:
        _plausibility(args, rig, op)
    return op


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
    from cmsim.dynamics import simulate
    from cmsim.faults import RollingSlip
    from cmsim.frequencies import rig_frequencies

    rig = _load_rig(args)
    op = _operating_point(args, rig)
    faults = _faults_of(args, rig)
    profile = _speed_profile(args)
    table, mesh_model = _resolve_mesh_options(args, rig, op.torque_nm)
    bar = None
    if not args.json and args.duration_s + args.warmup_s > LONG_RUN_S and _fits(args, rig):
        from tqdm import tqdm
        bar = tqdm(total=round(args.duration_s + args.warmup_s, 3), unit="sim s",
                   desc="cmsim simulate", file=sys.stderr, leave=False)

    def progress(done_s, total_s):
        bar.update(round(done_s, 3) - bar.n)

    slip = RollingSlip(cage_speed_rms=args.cage_slip, ball_rms_rad=args.ball_jitter_rad,
                       correlation_s=args.slip_correlation_s)
    _check_losses_options(args)
    try:
        run = simulate(rig, op, args.duration_s, fs_hz=args.fs_hz, substeps=args.substeps,
                       mesh=mesh_model if mesh_model is not None else table, slip=slip,
                       seed=args.seed, warmup_s=args.warmup_s, faults=faults, profile=profile,
                       progress=None if bar is None else progress, losses=args.losses or None)
    finally:
        if bar is not None:
            bar.close()
    if args.sensors or args.sensor_noise or args.sensor_fs_hz is not None:
        from cmsim.sensors import add_sensors
        run = add_sensors(run, noise_rms=args.sensor_noise, fs_hz=args.sensor_fs_hz)
    if args.out:
        run.save(args.out)
    freqs = rig_frequencies(rig, op)
    first = rig.bearing_names[0]
    out = {"shaft_hz": freqs.fr1_hz, "gmf_hz": freqs.gmf_hz,
           "bpf_hz": freqs.bearing(first).bpf_hz, **run.summary(),
           "faults": [f["label"] for f in run.meta["faults"]],
           "losses": _losses_summary(run.meta.get("losses")),
           "fault_frequencies": run.meta["fault_frequencies"],
           "speed_profile": run.meta["speed_profile"],
           "out": str(args.out) if args.out else None}
    return out


def _faults_of(args, rig):
    """The faults of the rig file's ``[[faults]]``, ``--faults FILE`` and each ``--fault``
    (in that order), each checked against ``rig``; bad input names the option that gave it."""
    from cmsim.faults import load_faults, parse_fault

    found = []                                    # (where, fault)
    for option, path in (("--rig", getattr(args, "rig", None)),
                         ("--faults", getattr(args, "faults", None))):
        if path:
            loaded = _load_file(option, path, load_faults, "a TOML file with a [[faults]] list")
            found += [(f"{option} {path}: faults[{i}] ({f.name})", f)
                      for i, f in enumerate(loaded)]
    for text in getattr(args, "fault", None) or ():
        try:
            found.append((f"--fault {text}", parse_fault(text)))
        except ParameterError as exc:
            raise CLIError(f"--fault {text}: {' '.join(str(exc).split())} (form: "
                           f"TYPE:key=value,...)", option="--fault") from None
        except TypeError as exc:                  # a required field left out
            missing = re.findall(r"'(\w+)'", str(exc))
            raise CLIError(f"--fault {text}: {', '.join(missing) or 'a parameter'} must be "
                           f"given (form: TYPE:key=value,...)", option="--fault") from None
    for where, fault in found:
        try:
            fault.validate(rig)
        except ParameterError as exc:
            raise CLIError(f"{where}: {' '.join(str(exc).split())}",
                           option=where.split()[0]) from None
    return tuple(f for _, f in found)


def _speed_profile(args):
    """The run-up / coast-down of ``--ramp-to-rpm`` and ``--ramp-s`` (None without them)."""
    if args.ramp_to_rpm is None:
        if args.ramp_s is not None or args.ramp_start_s is not None:
            raise CLIError("--ramp-s and --ramp-start-s shape the ramp of --ramp-to-rpm; give "
                           "--ramp-to-rpm too", option="--ramp-s")
        return None
    from cmsim.dynamics.profiles import SpeedProfile
    start_s = args.ramp_start_s or 0.0
    ramp_s = args.ramp_s if args.ramp_s is not None else max(
        args.warmup_s + args.duration_s - start_s, 1e-3)
    return SpeedProfile.ramp(args.speed_rpm, args.ramp_to_rpm, ramp_s, start_s=start_s)


#: simulated seconds above which simulate says how long it will take (realtime factor ~3-10)
LONG_RUN_S = 2.0


def _fits(args, rig):
    """False when simulate will refuse the run for its memory (then say nothing before)."""
    from cmsim.dynamics.simulate import check_memory
    try:
        check_memory(args.duration_s, args.fs_hz, rig)
    except (ParameterError, AttributeError, TypeError):
        return False
    return True


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


def _mesh_argument(args, torques_nm=()):
    """The ``mesh`` value the options name: a string, or the MeshTableSet / table of a file.

    A --mesh-table set of several torques is read between its tables only: a torque outside
    its range (--table-torque-nm, or --torque-nm without it) is refused, not clamped.
    """
    if args.table_torque_nm is not None and not args.mesh_table:
        raise CLIError("--table-torque-nm selects a table of --mesh-table FILE; give "
                       "--mesh-table too", option="--table-torque-nm")
    if not args.mesh_table:
        return args.mesh
    if args.mesh != "hybrid-tables":
        raise CLIError(f"--mesh {args.mesh} and --mesh-table exclude each other",
                       option="--mesh")
    from cmsim.mesh_stiffness.table_set import MeshTableSet
    tables = _load_file("--mesh-table", args.mesh_table, MeshTableSet.load,
                        "a mesh stiffness table file (cmsim mesh-table --out)")
    known = [float(t.torque_nm) for t in tables.tables]
    if len(known) > 1:
        lo, hi = min(known), max(known)
        asked = ([("--table-torque-nm", args.table_torque_nm)]
                 if args.table_torque_nm is not None
                 else [("--torque-nm", q) for q in torques_nm])
        for option, q in asked:
            if not lo - 1e-9 * hi <= q <= hi + 1e-9 * hi:
                raise CLIError(f"{option} {q:g} is outside the torques of --mesh-table "
                               f"{args.mesh_table}: allowed [{lo:g}, {hi:g}] N m (tables "
                               f"at {', '.join(f'{x:g}' for x in known)})", option=option)
    return tables if args.table_torque_nm is None else tables.at(args.table_torque_nm)


def _resolve_mesh_options(args, rig, torque_nm):
    """(mesh_table, mesh_model) of the mesh options at ``torque_nm`` (resolve_mesh)."""
    from cmsim.dynamics.tooth_contact import resolve_mesh
    mesh = _mesh_argument(args, [torque_nm])
    if rig.gears is None and args.mesh_table:
        raise CLIError("--mesh-table needs a rig with gears", option="--mesh-table")
    return resolve_mesh(rig, mesh, torque_nm, progress=False if args.json else None)


def _text_simulate(res):
    lines = [f"simulated {res['sim_s']:.3f} s in {res['wall_s']:.3f} s "
             f"(realtime factor {res['realtime_factor']:.1f}, compile {res['compile_s']:.1f} s)",
             f"shaft {res['shaft_hz']:.3f} Hz, ball pass {res['bpf_hz']:.3f} Hz"]
    if res["gmf_hz"] is not None:
        lines.append(f"GMF {res['gmf_hz']:.2f} Hz; DTE mean {res['dte_mean_um']:.3f} um, "
                     f"rms {res['dte_rms_um']:.3f} um (mean {res['dte_mean_rad']:.3e} rad)")
    if res.get("speed_profile"):
        prof = res["speed_profile"]
        lines.append(f"speed profile: {prof['speeds_rpm'][0]:g} -> {prof['speeds_rpm'][-1]:g} "
                     f"rpm over {prof['times_s'][-1]:g} s")
    if res.get("losses"):
        lo = res["losses"]
        parts = ", ".join(f"{k.replace('_', ' ')} {v:.3g}" for k, v in lo["power_w"].items()
                          if v > 0)
        line = f"losses {lo['total_loss_w']:.4g} W ({parts}); efficiency " \
               f"{100 * lo['efficiency']:.2f} %"
        if lo.get("closure") is not None:
            line += f" (the run's power balance closes to {100 * lo['closure']:.3f} %)"
        lines.append(line)
    for label, freqs in (res.get("fault_frequencies") or {}).items():
        lines.append(f"fault {label}: " + ", ".join(
            f"{k[:-3].upper()} {v:.3f} Hz" for k, v in freqs.items()
            if k.endswith("_hz") and isinstance(v, (int, float))))
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
    p.add_argument("--sensors", action="store_true",
                   help="add housing accelerometers accel_<bearing>_<x|y> (m/s^2, bearing "
                        "forces through the rig's [housing] modes) and a once-per-rev tacho "
                        "(implied by --sensor-noise or --sensor-fs-hz)")
    p.add_argument("--sensor-noise", type=float, default=0.0, metavar="RMS",
                   help="white sensor noise, m/s^2 rms (seeded by --seed)")
    p.add_argument("--sensor-fs-hz", type=float, metavar="FS",
                   help="sensor sample rate, Hz (<= --fs-hz, e.g. 12000); the whole run is "
                        "decimated through an 80 dB anti-alias filter")
    _add_fault_options(p)
    _add_losses_option(p)
    p.add_argument("--ramp-to-rpm", type=float, metavar="RPM",
                   help="run-up / coast-down: the input speed goes linearly from --speed-rpm "
                        "to RPM (the cage, mesh and input rotation follow; --sensors adds "
                        "the tacho for order tracking)")
    p.add_argument("--ramp-s", type=float, metavar="S",
                   help="duration of the ramp, s (default: to the end of the record)")
    p.add_argument("--ramp-start-s", type=float, metavar="S",
                   help="constant speed until S, then the ramp, s from the start of the "
                        "warm-up (default 0)")
    _add_rig_options(p)
    p.set_defaults(func=_cmd_simulate, text=_text_simulate)


def _check_losses_options(args):
    if getattr(args, "losses", False) and getattr(args, "friction", None) is not None:
        raise CLIError("--losses sets the tooth friction from the lubricant film along the "
                       "path; leave out --friction", option="--friction")


def _losses_summary(info):
    """The ``losses`` of a run's meta for the CLI: power by source (W), total, efficiency
    (the run's power balance where there is one, else quasi-static) and the balance's
    closure."""
    if not info:
        return None
    qs, bal = info["quasi_static"], info.get("balance")
    return {"power_w": qs["power_w"], "total_loss_w": qs["total_loss_w"],
            "efficiency": bal["efficiency"] if bal else qs["efficiency"],
            "quasi_static_efficiency": qs["efficiency"],
            "closure": bal["closure"] if bal else None,
            "balance_losses_w": bal["losses_w"] if bal else None}


def _add_losses_option(p):
    p.add_argument("--losses", action="store_true",
                   help="every loss source in the run: windage, pumping and bearing friction "
                        "torques resist the rotations, the tooth friction follows the "
                        "mixed-lubrication film (paper 000, 004); the run's meta carries the "
                        "breakdown by source and its power balance")


def _add_fault_options(p):
    p.add_argument("--fault", action="append", metavar="TYPE:key=value,...",
                   help="a fault of the catalogue, felt through the dynamics (repeatable), "
                        "e.g. outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4 or "
                        "tooth_crack:gear=1,depth_m=1e-3; types: " + ", ".join(FAULT_NAMES)
                        + "; a rig file's [[faults]] list is applied too")
    p.add_argument("--faults", metavar="FILE.toml",
                   help="faults from a TOML file's [[faults]] list (type = \"...\", fields)")


#: the catalogue's names for --help (cmsim.faults.FAULT_TYPES; not imported at start-up, it
#: pulls in the mesh-stiffness stack; tests check the two agree)
FAULT_NAMES = ("outer_race", "inner_race", "ball", "wear", "off_size_ball", "rolling_slip",
               "eccentricity", "tooth_crack", "tooth_spall", "tooth_breakage", "profile_error",
               "speed_fluctuation", "torque_ripple")


# ---------------------------------------------------------------------- modes
def _cmd_modes(args):
    from cmsim.dynamics.modal import modal_analysis
    rig = _load_rig(args)
    op = _operating_point(args, rig)
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

    def load(path):
        run = Run.load(path)
        run.rig, run.operating_point  # noqa: B018 - parse the meta now: a bad one is bad input
        return run

    run = _load_file("RUN.npz", args.run, load, "a cmsim run file (cmsim simulate --out)")
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

    rig = _load_file("--rig", args.rig, Rig.load, "a rig TOML file") if args.rig \
        else Rig.paper_2016()
    torques = args.torque_nm if args.torque_nm is not None else (
        [0.0] if rig.gears is not None else None)
    if args.torque_nm is not None and rig.gears is None:
        raise CLIError("--torque-nm needs a rig with gears (this rig has none; use "
                       "--radial-load-n)", option="--torque-nm")
    if args.radial_load_n is not None and rig.gears is not None:
        raise CLIError("--radial-load-n loads the rotor of a bearing rig; a gear rig is "
                       "loaded by --torque-nm", option="--radial-load-n")
    from cmsim.rig import OperatingPoint
    _plausibility(args, rig, OperatingPoint(args.speed_rpm[0], max(torques or [0.0]),
                                            args.radial_load_n or 0.0))
    mesh = _mesh_argument(args, torques or ())
    _check_losses_options(args)
    if mesh == "hybrid-tables" and rig.gears is not None:
        # build (or load) the rig's tables once, before the workers start
        from cmsim.dynamics.tooth_contact import hybrid_table_set
        hybrid_table_set(rig, progress=False if args.json else None)
    spec = SweepSpec(speeds_rpm=args.speed_rpm, torques_nm=torques,
                     radial_load_n=args.radial_load_n,
                     duration_s=args.duration_s, frictions=args.friction or (None,),
                     clearances_m=args.clearance_m or (None,), rig=rig, fs_hz=args.fs_hz,
                     warmup_s=args.warmup_s, substeps=args.substeps, seed=args.seed,
                     seed_policy=args.seed_policy, mesh=mesh, faults=_faults_of(args, rig),
                     losses=args.losses or None)
    progress = not args.json and sys.stderr.isatty()
    try:
        summary = run_sweep(spec, args.out, workers=args.workers, force=args.force,
                            progress=progress)
    except KeyboardInterrupt:
        raise CLIError(f"interrupted; finished runs are kept in {args.out}/manifest.json, "
                       f"re-run the same command to resume", 130) from None
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
    p.add_argument("--torque-nm", type=float, nargs="+",
                   help="output torques, N m (gear rigs; default 0: unloaded, the teeth may "
                        "separate)")
    p.add_argument("--radial-load-n", type=float, metavar="N",
                   help="static radial load on the rotor of a bearing rig, N (default 0)")
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
    _add_fault_options(p)
    _add_losses_option(p)
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=_cmd_sweep, text=_text_sweep)


# ---------------------------------------------------------------------- dataset
def _cmd_dataset(args):
    from cmsim.datasets import DatasetSpec, generate_dataset

    spec = _load_file("SPEC", args.spec, DatasetSpec.load, "a dataset spec TOML file")
    if not args.json and _numba_cache_cold():       # after the spec is known to be good
        print("cmsim: compiling numba kernels (first run only, about 30 s)...", file=sys.stderr)
    progress = not args.json and sys.stderr.isatty()
    try:
        summary = generate_dataset(spec, args.out, workers=args.workers,
                                   scheduler=args.scheduler, progress=progress,
                                   verify=args.verify, force=args.force)
    except KeyboardInterrupt as exc:
        raise CLIError(f"interrupted ({getattr(exc, 'signal_name', 'SIGINT')}); finished "
                       f"records are kept in {args.out}, re-run the same command to resume",
                       130) from None
    res = summary.to_dict()
    if summary.records_failed:
        _warn(args, f"{summary.records_failed} records failed (status 'failed' in "
                    f"{res['manifest']}, with their error)")
    return res


def _text_dataset(res):
    lines = [f"{res['records_total']} records in {res['dir']}: {res['records_written']} "
             f"written, {res['records_skipped']} already there, {res['records_failed']} failed",
             f"wall {res['wall_s']:.2f} s on {res['workers']} {res['runner']} workers; "
             f"integration {res['integration_s']:.2f} s, setup {res['setup_s']:.2f} s, "
             f"sensors {res['sensors_s']:.2f} s, save {res['save_s']:.2f} s",
             f"manifest {res['manifest']}"]
    lines += [f"failed {f['record_id']}: {f['error']}" for f in res["failed"][:5]]
    return "\n".join(lines)


def _add_dataset(sub):
    p = sub.add_parser("dataset", help="generate a labelled fault dataset from a TOML spec",
                       description="Generate the records of a dataset spec (datasets/*.toml) "
                                   "on local worker processes or a Dask cluster; each record "
                                   "is saved to DIR/records/ as it finishes and listed in "
                                   "DIR/manifest.parquet. Re-running the same command "
                                   "resumes: finished records are not recomputed.")
    p.add_argument("spec", metavar="SPEC", help="dataset spec (TOML)")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="dataset directory")
    p.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: number of CPUs)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="dask.distributed scheduler address (tcp://host:8786); its workers "
                        "must see DIR (needs the 'dask' extra)")
    p.add_argument("--verify", action="store_true",
                   help="check the SHA-256 of every finished record when resuming")
    p.add_argument("--force", action="store_true",
                   help="replace a dataset of a different spec in DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=_cmd_dataset, text=_text_dataset)


# ---------------------------------------------------------------------- report
def _cmd_report(args):
    from cmsim.report import DEFAULT_SIGNALS, build_report

    try:
        res = build_report(args.dir, tuple(args.signal) if args.signal else DEFAULT_SIGNALS,
                           top_n=args.top, max_freq_hz=args.max_hz,
                           progress=not args.json and sys.stderr.isatty())
    except ParameterError as exc:
        if exc.param is None:  # about the directory or its runs
            raise CLIError(f"DIR {args.dir}: {exc}", option="DIR") from None
        raise
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


# ---------------------------------------------------------------------- evaluate
def _cmd_evaluate(args):
    from cmsim.diagnostics import evaluate, load_algorithm, load_dataset
    from cmsim.diagnostics.report import write_report

    if args.train or args.test is not None or args.classifier is not None:
        return _cmd_syn2real(args)
    if args.dir is None:
        raise CLIError("DIR is required (or --train DIR --test FOLDER --classifier NAME)",
                       option="DIR")
    if args.algorithm is None:
        raise CLIError("argument --algorithm: is required with DIR (see cmsim evaluate "
                       "--help)", option="--algorithm")
    func = load_algorithm(args.algorithm)
    try:
        dataset = load_dataset(args.dir)
    except ParameterError as exc:  # the message starts with the directory
        raise CLIError(f"DIR {exc}", option="DIR") from None
    if len(dataset.manifest) == 0:
        raise CLIError(f"DIR {args.dir}: the dataset has no records", option="DIR")
    progress = None
    if not args.json and sys.stderr.isatty():
        def progress(done, total):
            print(f"\rcmsim evaluate: {done}/{total} records", end="", file=sys.stderr,
                  flush=True)
    ev = evaluate(dataset, func, progress=progress)
    if progress is not None:
        print(file=sys.stderr)
    out = ev.to_dict()
    out["algorithm"] = args.algorithm
    out["dataset"] = str(args.dir)
    out["report"] = str(write_report(ev, args.report)) if args.report else None
    return out


def _cmd_syn2real(args):
    from cmsim.datasets import load
    from cmsim.diagnostics.syn2real import evaluate_syn2real, measured_windows

    if args.dir is not None or args.algorithm is not None:
        raise CLIError("--train: give either DIR --algorithm NAME or --train DIR --test FOLDER "
                       "--classifier NAME, not both", option="--train")
    for opt, value in (("--train", args.train), ("--test", args.test),
                       ("--classifier", args.classifier)):
        if not value:
            raise CLIError(f"{opt} is required with --train/--test/--classifier", option=opt)
    if args.report is not None:
        raise CLIError("--report: not available with --train (use --json)", option="--report")
    for d in args.train:
        try:
            ds = load(d)
        except ParameterError as exc:
            raise CLIError(f"--train {exc}", option="--train") from None
        if len(ds) == 0:
            raise CLIError(f"--train {d}: the dataset has no ok record", option="--train")
    try:
        test = measured_windows(args.test, window=args.window,
                                max_windows=args.max_test_windows)
    except (ParameterError, OSError, ValueError, KeyError) as exc:
        raise CLIError(f"--test {args.test}: {exc}", option="--test") from None
    out = evaluate_syn2real(args.train, args.test, args.classifier, test=test,
                            seed=args.seed or 0)
    out["train"] = [str(d) for d in args.train]
    return out


def _text_syn2real(res):
    def ms(v):
        return f"{100 * v['mean']:.1f} +- {100 * v['std']:.1f} %"
    lines = [f"{res['classifier']} trained on {len(res['train'])} synthetic set(s), tested on "
             f"{res['test']} ({res['n_test_windows']} windows of {res['window']} samples, "
             f"{res['n_test_records']} records)",
             f"balanced accuracy {ms(res['balanced_accuracy'])}, macro-AUROC "
             f"{ms(res['macro_auroc'])}",
             "recall: " + ", ".join(f"{c} {ms(v)}" for c, v in res["per_class_recall"].items()),
             "confusion (rows truth, summed over runs): " + str(res["confusion_matrix"])]
    return "\n".join(lines)


def _text_evaluate(res):
    if "classifier" in res:
        return _text_syn2real(res)
    m = res["metrics"]
    lines = [f"{res['algorithm']} on {res['dataset']}: {m['n_scored']}/{m['n_records']} "
             f"records answered, {m['n_failed']} raised",
             f"accuracy {m['accuracy']:.3f} (chance {m['chance_accuracy']:.3f}), macro-F1 "
             f"{m['macro_f1']:.3f}" if m["n_scored"] else "no record answered"]
    if m["auc"]:
        lines.append("ROC AUC: " + ", ".join(
            f"{k} {v:.3f}" for k, v in m["auc"].items() if v == v))
    det = m["detection"]
    if m["n_scored"] and det["threshold"] is None or det["threshold"] != det["threshold"]:
        lines.append("no healthy record answered: detection against severity not scored")
    for cls, c in det["classes"].items() if det["threshold"] == det["threshold"] else ():
        lines.append(f"{cls}: detected {c['detection_rate_all']:.2f} at 5 % false alarms, "
                     f"smallest severity detected {c['min_detected_severity']:.3g}")
    for rid, err in res["errors"].items():
        lines.append(f"record {rid}: {err}")
    if res["report"]:
        lines.append(f"wrote {res['report']}")
    return "\n".join(lines)


def _add_evaluate(sub):
    p = sub.add_parser("evaluate", help="score a diagnostic algorithm on a dataset",
                       description="Run a diagnostic function over every record of a dataset "
                                   "(cmsim dataset --out, or a folder of measured records with "
                                   "metadata.json) and report accuracy, macro-F1, the confusion "
                                   "matrix, per-class ROC AUC and detection against severity at "
                                   "5 %% false alarms. See cmsim.diagnostics for the function's "
                                   "signature.")
    p.add_argument("dir", type=Path, metavar="DIR", nargs="?", help="dataset directory")
    p.add_argument("--algorithm", metavar="MODULE:FUNCTION",
                   help="built-in (envelope, tsa, sideband), package.module:function or "
                        "path/file.py:function (required with DIR)")
    p.add_argument("--train", type=Path, nargs="+", metavar="DIR",
                   help="sim-to-real: generated dataset(s) to train on (one per seed; mean "
                        "and std over them)")
    p.add_argument("--test", type=Path, metavar="FOLDER",
                   help="sim-to-real: folder of measured records (metadata.json)")
    p.add_argument("--classifier", choices=("envelope", "forest", "logistic"),
                   help="sim-to-real classifier (cmsim.diagnostics.syn2real)")
    p.add_argument("--window", type=int, metavar="N",
                   help="sim-to-real: samples per window (default ~0.34 s: 4096 at 12 kHz)")
    p.add_argument("--max-test-windows", type=int, metavar="N",
                   help="sim-to-real: first N windows of each test record only")
    p.add_argument("--seed", type=int, help="sim-to-real: random state of the learned model")
    p.add_argument("--report", type=Path, metavar="OUT.html",
                   help="write an HTML page with the plots")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=_cmd_evaluate, text=_text_evaluate)


# ---------------------------------------------------------------------- compare
def _cmd_compare(args):
    from cmsim.discrepancy import compare, read_record
    from cmsim.discrepancy.report import write_report

    rig = _load_file("--rig", args.rig, _rig_loader(), "a rig TOML file") if args.rig else None
    record = read_record(args.record, channel=args.channel, rig=rig)
    kw = {} if args.budget is None else {"budget": args.budget}
    res = compare(record, seed=args.seed, **kw)
    out = res.to_dict()
    out["report"] = str(write_report(res, args.report)) if args.report else None
    return out


def _rig_loader():
    from cmsim.rig import Rig
    return Rig.load


def _text_compare(res):
    lines = [f"finding: {res['finding']}" + (f" on {res['component']}" if res["component"]
                                              else "") + (f" {res['parameters']}"
                                                          if res["parameters"] else "")]
    g = res["gain"]
    lines.append(f"held-out discrepancy (chi2 per feature): {g['before']:.3g} -> "
                 f"{g['after']:.3g} (relative gain {g['relative']:.2f})")
    for c in res["causes"][:5]:
        lines.append(f"  {c['name']:20s} {str(c['component']):10s} score {c['score']:.3f}")
    for d in res["discrepancies"][:5]:
        lines.append(f"  {d['feature']:24s} measured {d['measured']:.3g} simulated "
                     f"{d['simulated']:.3g} (z {d['z']:.1f})")
    for k, v in res["inferred"].items():
        lines.append(f"inferred {k}: {v['value']:.6g} ({v['how']})")
    lines.append(f"{res['simulations']} simulations, {res['wall_s']:.1f} s")
    if res["report"]:
        lines.append(f"wrote {res['report']}")
    return "\n".join(lines)


def _add_compare(sub):
    p = sub.add_parser("compare", help="compare a measured record with the model, name the "
                                       "cause, fit it and measure the gain",
                       description="RECORD is a .npz/.csv/.wav file in a folder whose "
                                   "metadata.json gives rig, fs, speed and load (relative "
                                   "paths are also looked up under CMSIM_DATA). The answer "
                                   "key (condition, fault fields, file name) is never read.")
    p.add_argument("record", metavar="RECORD", help="measured recording")
    p.add_argument("--channel", metavar="NAME", help="channel (default: the first near a "
                                                     "documented bearing)")
    p.add_argument("--rig", metavar="FILE.toml",
                   help="model rig (default: built from metadata.json geometry)")
    p.add_argument("--report", type=Path, metavar="DIR", help="write DIR/compare.html")
    p.add_argument("--budget", type=int, default=None, metavar="N",
                   help="most simulations: ranking, fit and held-out re-simulations "
                        "(default 140, at least 10)")
    p.add_argument("--seed", type=int, default=0, help="seed of the model simulations")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.set_defaults(func=_cmd_compare, text=_text_compare)


# ---------------------------------------------------------------------- losses
def _cmd_losses(args):
    from cmsim.losses import LossSettings, operating_losses
    rig = _load_rig(args)
    op = _operating_point(args, rig)
    settings = LossSettings(air_pressure_pa=args.air_pressure_pa,
                            air_temperature_c=args.air_temperature_c,
                            oil_jet_kg_s=args.oil_jet_kg_s, roughness_m=args.roughness_m)
    table, _ = _resolve_mesh_options(args, rig, op.torque_nm)
    res = operating_losses(rig, op, settings, table).to_dict()
    res["rig"] = rig.name
    res["plot"] = None
    if args.plot:
        from cmsim.losses.plots import loss_breakdown_figure
        top = max(13000.0, op.speed_rpm)
        fig = loss_breakdown_figure(rig, np.linspace(top / 13.0, top, 13), op.torque_nm,
                                    settings)
        _save_figure(fig, args.plot)
        res["plot"] = str(args.plot)
    return res


def _text_losses(res):
    lines = [f"losses of {res['rig']} at {res['speed_rpm']:g} rpm, {res['torque_nm']:g} N m",
             f"{'source':>16}  {'power_W':>10}"]
    for name, value in res["power_w"].items():
        lines.append(f"{name:>16}  {value:10.3f}")
    lines += [f"{'total':>16}  {res['total_loss_w']:10.3f}",
              f"output {res['output_power_w']:.1f} W, input {res['input_power_w']:.1f} W, "
              f"efficiency {100 * res['efficiency']:.2f} % (load-independent "
              f"{res['load_independent_w']:.2f} W, load-dependent {res['load_dependent_w']:.2f} W)"]
    if res["plot"]:
        lines.append(f"wrote {res['plot']}")
    return "\n".join(lines)


def _add_losses(sub):
    p = sub.add_parser("losses", help="power losses by source and the efficiency",
                       description="Windage and meshing torques (paper 000 eq. 25-28), oil "
                                   "jet, Harris-Palmgren bearing torques and mixed-lubrication "
                                   "tooth friction (paper 004 eq. 21) at one operating point; "
                                   "the load sharing of the tooth pairs comes from the mesh "
                                   "model a run would use (--mesh), so the figures match "
                                   "cmsim simulate --losses.")
    p.add_argument("--speed-rpm", type=float, required=True, help="input speed, rpm")
    p.add_argument("--torque-nm", type=float, required=True, help="output torque, N m")
    p.add_argument("--air-pressure-pa", type=float, default=101325.0,
                   help="air pressure around the gears, Pa")
    p.add_argument("--air-temperature-c", type=float, default=20.0, help="air temperature, C")
    p.add_argument("--oil-jet-kg-s", type=float, default=0.0,
                   help="radial oil-jet mass flow per gear, kg/s")
    p.add_argument("--roughness-m", type=float,
                   help="composite RMS roughness of the teeth, m (default: the rig's)")
    p.add_argument("--plot", type=Path, metavar="FILE.png",
                   help="write the loss breakdown against speed (paper 000 Figs. 53-57)")
    _add_mesh_options(p)
    _add_rig_options(p, friction=False)
    p.set_defaults(func=_cmd_losses, text=_text_losses)


# ---------------------------------------------------------------------- main
def build_parser():
    """The argparse parser of ``cmsim``."""
    parser = _Parser(
        prog="cmsim", description="Vibration of a spur-gear transmission on ball bearings "
                                  "(19-DOF model of Fernandez-del-Rincon et al. 2016).")
    from cmsim import __version__
    parser.add_argument("--version", action="version", version=f"cmsim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for add in _COMMANDS:
        add(sub)
    _apply_ranges(parser)
    return parser


# ---------------------------------------------------------------------- mesh-table
def _cmd_mesh_table(args):
    import time

    from cmsim.dynamics.torque_tables import torque_tables

    rig = _load_rig(args)
    if rig.gears is None:
        raise CLIError(f"--rig {args.rig}: mesh-table needs a rig with gears", option="--rig")
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
             _add_dataset, _add_report, _add_evaluate, _add_compare, _add_losses]


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


# ---------------------------------------------------------------------- validation
# The one way the CLI validates, names and reports:
# 1. every numeric option has its allowed range here (keyed by argparse dest, or by
#    (command, dest) where a command differs); argparse checks it while parsing, so the
#    message names the option as typed ("argument --top: must be an integer in [1, 1000]");
# 2. every ParameterError raised by the library carries the Python name of its parameter
#    (``.param``); _user_message rewrites it, and any other Python name of an option of the
#    command, into the option (``max_peaks`` → ``--top``) through _PARAM_TO_DEST;
# 3. files named by options are checked (_check_paths) or loaded through _load_file, which
#    turns any reading error into one line naming the option;
# 4. anything else is an internal error: exit 1, one line, "please report".
# tests/test_cli_contract.py checks that every numeric option of every command is in
# _RANGES or listed in _LIBRARY_VALIDATED, and runs a catalogue of bad inputs.
_INF = math.inf
#: dest (or (command, dest)) -> (type, lo, hi, lo_open, hi_open, unit)
_RANGES = {
    "speed_rpm": (float, 0.0, 1.0e5, True, False, "rpm"),
    "torque_nm": (float, 0.0, 1.0e6, False, False, "N m"),
    ("mesh-table", "torque_nm"): (float, 0.0, 1.0e6, True, False, "N m"),
    "table_torque_nm": (float, 0.0, 1.0e6, False, False, "N m"),
    "radial_load_n": (float, 0.0, 1.0e7, False, False, "N"),
    "duration_s": (float, 0.0, 600.0, True, False, "s"),
    "fs_hz": (float, 1.0e3, 1.0e7, False, False, "Hz"),
    "substeps": (int, 1, 1000, False, False, ""),
    "warmup_s": (float, 0.0, 60.0, False, False, "s"),
    "clearance_m": (float, -1.0e-3, 1.0e-3, False, False, "m"),
    "friction": (float, 0.0, 0.3, False, False, ""),
    "cage_slip": (float, 0.0, 0.2, False, False, ""),
    "ball_jitter_rad": (float, 0.0, 0.05, False, False, "rad"),
    "slip_correlation_s": (float, 1.0e-5, 10.0, False, False, "s"),
    "seed": (int, 0, 2 ** 32 - 1, False, False, ""),
    "positions": (int, 4, 1000, False, False, ""),
    "steps": (int, 8, 100_000, False, False, ""),
    "top": (int, 1, 1000, False, False, ""),
    ("report", "top"): (int, 1, 100, False, False, ""),
    "threshold_db": (float, 0.0, 200.0, False, False, "dB"),
    "max_hz": (float, 0.0, 1.0e7, True, False, "Hz"),
    "resolution_hz": (float, 0.0, 1.0e6, True, False, "Hz"),
    "band_hz": (float, 0.0, 1.0e7, False, False, "Hz"),
    "workers": (int, 1, 1024, False, False, ""),
    "sensor_noise": (float, 0.0, 1.0e6, False, False, "m/s^2"),
    "sensor_fs_hz": (float, 0.0, 1.0e7, True, False, "Hz (and <= --fs-hz)"),
    "ramp_to_rpm": (float, 0.0, 1.0e5, True, False, "rpm"),
    "ramp_s": (float, 0.0, 1.0e5, True, False, "s"),
    "ramp_start_s": (float, 0.0, 1.0e5, False, False, "s"),
    "budget": (int, 10, 10000, False, False, ""),
    "air_pressure_pa": (float, 0.0, 1.0e7, True, False, "Pa"),
    "air_temperature_c": (float, -100.0, 500.0, False, False, "C"),
    "oil_jet_kg_s": (float, 0.0, 100.0, False, False, "kg/s"),
    "roughness_m": (float, 0.0, 5.0e-5, True, False, "m"),
    "window": (int, 256, 1 << 20, False, False, ""),
    "max_test_windows": (int, 1, 100_000, False, False, ""),
}
#: numeric options whose range depends on other inputs and is checked by the library, which
#: names them through _PARAM_TO_DEST (none today; clearance is narrowed by the bearing)
_LIBRARY_VALIDATED = set()
#: Python names used by the library -> dest of the option that sets them
_PARAM_TO_DEST = {
    "max_peaks": "top", "top_n": "top", "n_positions": "positions",
    "cage_speed_rms": "cage_slip", "ball_rms_rad": "ball_jitter_rad",
    "correlation_s": "slip_correlation_s", "n_steps": "steps", "torques_nm": "torque_nm",
    "speeds_rpm": "speed_rpm", "friction_coefficient": "friction", "frictions": "friction",
    "clearances_m": "clearance_m", "max_freq_hz": "max_hz", "signals": "signal",
    "mesh": "mesh", "method": "method", "centres": "centres",
    "noise_rms": "sensor_noise", "fs_out_hz": "sensor_fs_hz",
    "algorithm": "algorithm", "dataset": "dir",
}
#: one-word Python names the library uses in messages for what an option sets
_ALWAYS_REWRITE = {"substeps"}
#: path options: dest -> "file" (must exist), "dir" (must exist), "out" (new file), "outdir"
_PATHS = {"rig": "file", "faults": "file", "mesh_table": "file", "run": "file", "dir": "dir",
          "out": "out",
          "plot": "out", ("sweep", "out"): "outdir", ("evaluate", "report"): "out",
          ("dataset", "spec"): "file", ("dataset", "out"): "outdir",
          ("compare", "report"): "outdir", ("evaluate", "train"): "dir",
          ("evaluate", "test"): "dir"}


class CLIError(Exception):
    """An error the CLI reports in one line, with its exit status and JSON extras."""

    def __init__(self, message, status=2, *, option=None, extra=None):
        super().__init__(message)
        self.status, self.option, self.extra = status, option, dict(extra or {})


class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting (one line, --json aware).

    Abbreviated options are refused (``--torque`` is not ``--torque-nm``): an abbreviation
    that works today would silently mean another option when one is added.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message):
        raise CLIError(f"{message} (see {self.prog} --help)", 2, option=_option_in(message))


def _option_in(message):
    m = re.search(r"argument ([^\s:]+)", message)
    return m.group(1).split("/")[-1] if m else None


def _ranged(kind, lo, hi, lo_open, hi_open, unit):
    """argparse type: a number of ``kind`` within the range, else a message with the range."""
    from cmsim.errors import format_range

    allowed = format_range(lo, hi, lo_open=lo_open, hi_open=hi_open, unit=unit,
                           integer=kind is int)

    def parse(text):
        try:
            v = int(text) if kind is int else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {allowed}, got {text!r}") from None
        if (not math.isfinite(v) or v < lo or v > hi or (lo_open and v == lo)
                or (hi_open and v == hi)):
            raise argparse.ArgumentTypeError(f"must be {allowed}, got {text}")
        return v

    parse.__name__ = kind.__name__
    parse.allowed = allowed
    return parse


def _subparsers(parser):
    """{command: subparser} of the ``cmsim`` parser."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _option_name(action):
    """The option as a user types it (``--top``), or the metavar of a positional."""
    if action.option_strings:
        return max(action.option_strings, key=len)
    return action.metavar or action.dest.upper()


def _apply_ranges(parser):
    """Give every numeric option of every command its range (see _RANGES)."""
    for command, sub in _subparsers(parser).items():
        for action in sub._actions:
            if action.type in (int, float):
                rng = _RANGES.get((command, action.dest), _RANGES.get(action.dest))
                if rng is not None:
                    action.type = _ranged(*rng)


def _options_of(parser, command):
    """{dest: option} of one command."""
    sub = _subparsers(parser).get(command)
    if sub is None:
        return {}
    return {a.dest: _option_name(a) for a in sub._actions if a.dest != "help"}


def _user_message(exc, options):
    """The message of a ParameterError with Python names replaced by the options typed."""
    msg = " ".join(str(exc).split())
    param = getattr(exc, "param", None)
    names = {}
    for name, dest in list(_PARAM_TO_DEST.items()) + [(d, d) for d in options]:
        if dest in options:
            names[name] = options[dest]
    option = None
    if param and param.startswith("-"):
        option = param
    elif param in names:
        option = names[param]
    for name, opt in sorted(names.items(), key=lambda kv: -len(kv[0])):
        if name == param or "_" in name or name in _ALWAYS_REWRITE:
            msg = re.sub(rf"(?<![\w.\[\-]){re.escape(name)}(?![\w\[])", opt, msg)
    if option is not None and option not in msg:
        msg = f"{option}: {msg}"
    return msg, option


def _check_paths(args, command, options):
    """Input files exist and are files; outputs are not directories and have a parent."""
    for dest, option in options.items():
        kind = _PATHS.get((command, dest), _PATHS.get(dest))
        value = getattr(args, dest, None)
        if kind is None or value is None:
            continue
        if isinstance(value, list):                 # nargs="+": check each
            for v in value:
                _check_paths(argparse.Namespace(**{dest: v}), command, {dest: option})
            continue
        path = Path(value)
        if kind == "file" and not path.is_file():
            why = "is a directory" if path.is_dir() else "does not exist"
            raise CLIError(f"{option} {path}: {why} (expected a file)", option=option)
        if kind == "dir" and not path.is_dir():
            why = "is a file" if path.exists() else "does not exist"
            raise CLIError(f"{option} {path}: {why} (expected a directory)", option=option)
        if kind in ("out", "outdir"):
            if kind == "out" and path.is_dir():
                raise CLIError(f"{option} {path}: is a directory (expected a file name)",
                               option=option)
            if kind == "outdir" and path.exists() and not path.is_dir():
                raise CLIError(f"{option} {path}: is a file (expected a directory, new or "
                               f"an existing sweep)", option=option)
            if not path.resolve().parent.is_dir():
                raise CLIError(f"{option} {path}: directory {path.parent} does not exist",
                               option=option)


def _load_file(option, path, loader, what):
    """``loader(path)``, any failure to read it reported as one line naming ``option``."""
    import zipfile

    try:
        return loader(path)
    except ParameterError as exc:
        detail = getattr(exc, "detail", None) or str(exc)
        raise CLIError(f"{option} {path}: {detail}", option=option) from None
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile) as exc:
        raise CLIError(f"{option} {path}: not {what} ({type(exc).__name__}: "
                       f"{' '.join(str(exc).split()) or 'unreadable'})", option=option) from None


def _warn(args, text):
    """A plausibility warning: stderr (unless --json) and the result's "warnings" list, given
    with the result (an error stays one line; with --json its object lists them)."""
    args._warnings.append(text)


#: ISO 6336-5 allowable contact stress of through-hardened steel is ~1500 MPa (case-hardened
#: up to ~1650); a nominal stress above twice that is far beyond what steel gears carry
PLAUSIBLE_CONTACT_STRESS_PA = 2 * 1500e6
#: ISO 76 static load rating factor of deep-groove ball bearings, f0 ~ 12.3 N/mm²
_F0_N_PER_M2 = 12.3e6


def _plausibility(args, rig, op):
    """Warn about loads far beyond what the rig's steel gears or bearings carry."""
    if rig.gears is not None and op.torque_nm > 0:
        sigma = rig.gears.nominal_contact_stress_pa(op.torque_nm)
        if sigma > PLAUSIBLE_CONTACT_STRESS_PA:
            _warn(args, f"--torque-nm {op.torque_nm:g} gives a nominal contact stress of "
                        f"{sigma / 1e6:.0f} MPa on a {1e3 * rig.gears.driving.face_width_m:g} "
                        f"mm face (ISO 6336); steel gears carry about 1500 MPa (results far "
                        f"above {PLAUSIBLE_CONTACT_STRESS_PA / 1e6:.0f} MPa are not physical)")
    if rig.gears is None:
        b = rig.bearings[0]
        c0 = _F0_N_PER_M2 * b.n_balls * b.ball_diameter_m ** 2
        if op.radial_load_n == 0:
            _warn(args, "a bearing rig without --radial-load-n: the bearings carry no load and "
                        "every bearing force is zero")
        elif op.radial_load_n > 2 * c0:
            _warn(args, f"--radial-load-n {op.radial_load_n:g} N is more than twice the static "
                        f"load rating C0 ~ {c0:.0f} N of bearing 1b1 (ISO 76)")


def _numba_cache_cold():
    """True when the integration kernel has no up-to-date numba cache (first run compiles)."""
    import os

    try:
        import cmsim.dynamics as dyn
        src = Path(dyn.__file__).parent / "_rhs_kernels.py"
        places = [src.parent / "__pycache__"]
        if os.environ.get("NUMBA_CACHE_DIR"):
            places.append(Path(os.environ["NUMBA_CACHE_DIR"]))
        mtime = src.stat().st_mtime
        for place in places:
            for idx in place.rglob("_rhs_kernels.integrate_jit*.nbi") if place.is_dir() else ():
                if idx.stat().st_mtime >= mtime:
                    return False
        return True
    except OSError:
        return False


def _announce_compile(args):
    if not args.json and args.command in _COMPILING and _numba_cache_cold():
        print("cmsim: compiling numba kernels (first run only, about 30 s)...", file=sys.stderr)


_COMPILING = ("simulate", "modes", "mesh-table", "sweep")


def main(argv=None):
    """Entry point of the ``cmsim`` console script; returns the exit status.

    0 success, 1 internal error (please report), 2 bad input, 3 diverged integration, 130
    interrupted. With ``--json`` stdout holds exactly one JSON object, also on errors:
    ``{"error": message, "status": code, "option": "--top" or null}``.
    """
    import os

    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    want_json = "--json" in argv
    parser = build_parser()
    args = argparse.Namespace(json=want_json, command=argv[0] if argv else None)
    try:
        args = parser.parse_args(_plain_negative_numbers(argv))
        args._warnings = []
        options = _options_of(parser, args.command)
        try:
            _check_paths(args, args.command, options)
            _announce_compile(args)
            res = args.func(args)
        except ParameterError as exc:
            msg, option = _user_message(exc, options)
            raise CLIError(msg, 2, option=option) from None
        except IntegrationDiverged as exc:
            msg, option = _user_message(exc, options)
            extra = {}
            if getattr(exc, "summary", None) is not None:
                extra["summary"] = exc.summary.to_dict()
            raise CLIError(msg, 3, option=option, extra=extra) from None
    except CLIError as exc:
        return _fail(args, str(exc), exc.status, exc.option, exc.extra)
    except KeyboardInterrupt:
        return _fail(args, "interrupted", 130)
    except Exception as exc:  # noqa: BLE001 - the last line of defence
        if os.environ.get("CMSIM_DEBUG"):
            raise
        detail = " ".join(str(exc).split())[:300]
        return _fail(args, f"internal error ({type(exc).__name__}: {detail}); please report "
                           f"it with the command line (CMSIM_DEBUG=1 shows the traceback)", 1)
    if isinstance(res, dict) and args._warnings:
        res = {**res, "warnings": list(args._warnings)}
        if not args.json:
            for text in args._warnings:
                print(f"cmsim {args.command}: warning: {text}", file=sys.stderr)
    if args.json:
        print(json.dumps(_jsonable(res)))
    else:
        print(args.text(res))
    return 0


def _fail(args, message, status, option=None, extra=None):
    message = " ".join(str(message).split())
    prog = f"cmsim {args.command}" if getattr(args, "command", None) in _subparsers(
        build_parser()) else "cmsim"
    print(f"{prog}: error: {message}", file=sys.stderr)
    if getattr(args, "json", False):
        out = {"error": message, "status": status, "option": option, **(extra or {})}
        warnings = getattr(args, "_warnings", None)
        if warnings:
            out["warnings"] = list(warnings)
        print(json.dumps(_jsonable(out)))
    return status


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
