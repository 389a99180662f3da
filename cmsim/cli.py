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
    from cmsim.mesh_stiffness.table import MeshStiffnessTable
    from cmsim.spectra import rig_frequencies

    rig = _load_rig(args)
    op = _operating_point(args)
    table = MeshStiffnessTable.load(args.mesh_table) if args.mesh_table else None
    slip = SlipModel(cage_speed_rms=args.cage_slip, ball_rms_rad=args.ball_jitter_rad,
                     correlation_s=args.slip_correlation_s)
    run = simulate(rig, op, args.duration_s, fs_hz=args.fs_hz, substeps=args.substeps,
                   mesh_table=table, slip=slip, seed=args.seed, warmup_s=args.warmup_s)
    if args.out:
        run.save(args.out)
    freqs = rig_frequencies(rig, op)
    first = rig.bearing_names[0]
    out = {
        "shaft_hz": freqs["shaft_hz"],
        "gmf_hz": freqs.get("gmf_hz"),
        "bpf_hz": freqs[first]["bpf_hz"],
        "dte_mean_rad": None, "dte_rms_rad": None, "dte_mean_um": None, "dte_rms_um": None,
        "sim_s": run.meta["sim_s"], "wall_s": run.meta["wall_s"],
        "realtime_factor": run.meta["realtime_factor"], "compile_s": run.meta["compile_s"],
        "seed": run.meta["seed"], "n_samples": int(run.t.size), "fs_hz": run.fs_hz,
        "out": str(args.out) if args.out else None,
    }
    if rig.gears is not None:
        dte = run["dte"]
        out.update(dte_mean_rad=float(dte.mean()), dte_rms_rad=float(dte.std()),
                   dte_mean_um=float(run["dte_um"].mean()), dte_rms_um=float(run["dte_um"].std()))
    for b in rig.bearing_names:
        out[f"F_{b}_loa_mean_n"] = float(run[f"F_{b}_loa"].mean())
        out[f"F_{b}_loa_rms_n"] = float(run[f"F_{b}_loa"].std())
    return out


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
    p.add_argument("--fs-hz", type=float, default=75_000.0, help="output sample rate, Hz")
    p.add_argument("--substeps", type=int, default=1, help="integration steps per sample")
    p.add_argument("--warmup-s", type=float, default=0.05, help="discarded start, s")
    p.add_argument("--mesh-table", metavar="FILE.npz", help="pair stiffness table to use")
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
    res = modal_analysis(rig, _operating_point(args), n_positions=args.positions)
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
    _add_rig_options(p, friction=False)
    p.set_defaults(func=_cmd_modes, text=_text_modes)


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


_COMMANDS = [_add_simulate, _add_modes]


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


_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)(e[-+]?\d+)?$", re.IGNORECASE)


def _join_negative_values(argv):
    """``--clearance-m -1e-6`` → ``--clearance-m=-1e-6`` (argparse takes "-1e-6" for an option)."""
    out = []
    for arg in argv:
        if out and out[-1].startswith("--") and "=" not in out[-1] and _NEGATIVE_NUMBER.match(arg):
            out[-1] = f"{out[-1]}={arg}"
        else:
            out.append(arg)
    return out


def main(argv=None):
    """Entry point of the ``cmsim`` console script; returns the exit status."""
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(_join_negative_values(argv))
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
