"""``cmsim simulate``: one operating point → a run (.npz)."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

from cmsim.cli.contract import CLIError, load_file, ranged
from cmsim.cli.options import (add_fault_options, add_losses_option, add_mesh_options,
                               add_rig_options, add_sampling_options, check_losses_options,
                               faults_of, load_rig, mesh_argument, number, operating_point,
                               prepare_tables)
from cmsim.rig import SAMPLING, Range

#: Simulated seconds above which simulate shows a progress bar (realtime factor ~3-10).
LONG_RUN_S = 2.0


def register(sub):
    """Add the ``simulate`` parser."""
    p = sub.add_parser("simulate", help="simulate the rig at one operating point",
                       description="Integrate the model and write a run (.npz).")
    p.add_argument("--speed-rpm", type=number("speed_rpm"),
                   help="input shaft speed, rpm (required, unless --machine: its speed)")
    p.add_argument("--torque-nm", type=number("torque_nm"),
                   help="output torque, N m (default 0, or --machine's)")
    p.add_argument("--radial-load-n", type=number("radial_load_n"),
                   help="static radial load on shaft 1's centre node, N (bearing rigs; "
                        "default 0, or --machine's)")
    add_sampling_options(p)
    add_mesh_options(p)
    p.add_argument("--cage-slip", type=number("cage_slip"), default=0.0, metavar="FRACTION",
                   help="rms random cage-speed fluctuation (0.01 = 1 %%); spreads ball-pass lines")
    p.add_argument("--ball-jitter-rad", type=number("ball_jitter_rad"), default=0.0,
                   help="rms random angular deviation of each ball in its pocket, rad")
    p.add_argument("--slip-correlation-s", type=number("slip_correlation_s"), default=5e-3,
                   help="correlation time of the slip processes, s")
    p.add_argument("--out", type=Path, metavar="RUN.npz", help="write the run here")
    p.add_argument("--sensors", action="store_true",
                   help="add housing accelerometers accel_<bearing>_<x|y> (m/s^2, bearing "
                        "forces through the rig's [housing] modes) and a once-per-rev tacho "
                        "(implied by --sensor-noise or --sensor-fs-hz)")
    p.add_argument("--sensor-noise", type=number("sensor_noise_m_s2"), default=0.0,
                   metavar="RMS", help="white sensor noise, m/s^2 rms (seeded by --seed)")
    p.add_argument("--sensor-fs-hz", type=number("fs_hz"), metavar="FS",
                   help="sensor sample rate, Hz (<= --fs-hz, e.g. 12000); the whole run is "
                        "decimated through an 80 dB anti-alias filter")
    p.add_argument("--machine", metavar="MACHINE.toml",
                   help="a calibrated machine (cmsim calibrate): the run is made on its rig "
                        "at its sample rate and the record gets its sensor channel, the "
                        "model force through the machine's path plus its background")
    add_fault_options(p)
    add_losses_option(p)
    p.add_argument("--ramp-to-rpm", type=number("speed_rpm"), metavar="RPM",
                   help="run-up / coast-down: the input speed goes linearly from --speed-rpm "
                        "to RPM (the cage, mesh and input rotation follow; --sensors adds "
                        "the tacho for order tracking)")
    p.add_argument("--ramp-s", type=ranged(Range(0.0, 1.0e5, lo_open=True, unit="s")), metavar="S",
                   help="duration of the ramp, s (default: to the end of the record)")
    p.add_argument("--ramp-start-s", type=ranged(Range(0.0, 1.0e5, unit="s")), metavar="S",
                   help="constant speed until S, then the ramp, s from the start of the "
                        "warm-up (default 0)")
    add_rig_options(p)
    p.set_defaults(func=run, text=text)


def _speed_profile(args):
    """The run-up / coast-down of ``--ramp-to-rpm`` and ``--ramp-s`` (None without them)."""
    if args.ramp_to_rpm is None:
        if args.ramp_s is not None or args.ramp_start_s is not None:
            raise CLIError("--ramp-s and --ramp-start-s shape the ramp of --ramp-to-rpm; give "
                           "--ramp-to-rpm too", option="--ramp-s")
        return None
    from cmsim.dynamics.profiles import SpeedProfile
    end_s = round(args.warmup_s + args.duration_s, 12)    # no 0.060000000000000005
    start_s = Range(0.0, end_s, hi_open=True,
                    unit="s (the ramp starts before the record ends: warmup_s + duration_s)"
                    ).check("ramp_start_s", args.ramp_start_s or 0.0)
    ramp_s = args.ramp_s if args.ramp_s is not None else max(end_s - start_s, 1e-3)
    profile = SpeedProfile.ramp(args.speed_rpm, args.ramp_to_rpm, ramp_s, start_s=start_s)
    if start_s + ramp_s > end_s * (1 + 1e-9):
        args.warn(f"--ramp-s {ramp_s:g}: the ramp ends {start_s + ramp_s:g} s after the warm-up "
                  f"starts, the record at {end_s:g} s: it reaches "
                  f"{profile.speed_rpm_at(end_s):.0f} rpm, not --ramp-to-rpm "
                  f"{args.ramp_to_rpm:g}")
    return profile


def _warn_nyquist(args, rig, op):
    """Warn when the mesh or a ball pass at the run's fastest speed lies above the Nyquist
    frequency of the record written (the sensor rate, else --fs-hz)."""
    from cmsim.frequencies import lines_above_nyquist, rig_frequencies

    top = max(op.speed_rpm, args.ramp_to_rpm or 0.0)
    sensor = args.sensor_fs_hz is not None
    freqs = rig_frequencies(rig, dataclasses.replace(op, speed_rpm=top))
    for text in dict.fromkeys(lines_above_nyquist(
            freqs, args.sensor_fs_hz if sensor else args.fs_hz,
            rate="fs_out_hz" if sensor else "fs_hz",
            speed="ramp_to_rpm" if top > op.speed_rpm else "speed_rpm")):
        args.warn(text)


def run(args):
    """Simulate, optionally add the sensors, write the run; the summary as a dict."""
    from cmsim.dynamics import simulate
    from cmsim.faults import RollingSlip
    from cmsim.frequencies import rig_frequencies

    if args.out is not None and args.out.suffix.lower() != ".npz":
        raise CLIError(f"--out {args.out}: a run is written as .npz (cmsim reads it back as "
                       "one; cmsim export writes other formats)", option="--out")
    machine = None
    if args.machine:
        from cmsim.machine import Machine, twin_mesh
        machine = load_file("--machine", args.machine, Machine.load,
                            "a machine file (cmsim calibrate --out)")
        for option, given in (("--rig", args.rig), ("--fs-hz", args.fs_hz != SAMPLING.fs_hz),
                              ("--sensor-fs-hz", args.sensor_fs_hz is not None)):
            if given:
                raise CLIError(f"{option}: a --machine run is made on the machine's rig at its "
                               f"sample rate; leave out {option}", option=option)
        args.fs_hz = machine.fs_hz
        rig = machine.rig
        # the machine's operating point, as calibrated, where the options leave it out
        for name in ("speed_rpm", "torque_nm", "radial_load_n"):
            if getattr(args, name) is None:
                setattr(args, name, getattr(machine.op, name))
        if args.clearance_m is not None:
            rig = rig.with_clearance(args.clearance_m)
        if args.friction is not None:
            if rig.gears is None:
                raise CLIError("--friction needs a rig with gears", option="--friction")
            rig = rig.with_friction(args.friction)
    else:
        if args.speed_rpm is None:
            raise CLIError("--speed-rpm: required (the input shaft speed, rpm), unless "
                           "--machine gives it", option="--speed-rpm")
        rig = load_rig(args)
        args.torque_nm = 0.0 if args.torque_nm is None else args.torque_nm
        args.radial_load_n = 0.0 if args.radial_load_n is None else args.radial_load_n
    op = operating_point(args, rig)
    if machine is not None:
        op = dataclasses.replace(op, radial_load_angle_rad=machine.op.radial_load_angle_rad)
    faults = faults_of(args, rig)
    profile = _speed_profile(args)
    _warn_nyquist(args, rig, op)
    mesh = mesh_argument(args, rig, [op.torque_nm],
                         **({"default": twin_mesh(rig)} if machine is not None else {}))
    check_losses_options(args)
    prepare_tables(args, rig, mesh, [op.torque_nm])
    if args.sensor_fs_hz is not None:
        if args.sensor_fs_hz > args.fs_hz:
            raise CLIError(f"--sensor-fs-hz {args.sensor_fs_hz:g} must be <= --fs-hz "
                           f"{args.fs_hz:g}", option="--sensor-fs-hz")
        from cmsim.sensors import sensor_rate_ratio
        sensor_rate_ratio(args.fs_hz, args.sensor_fs_hz)     # refused before the run
    slip = RollingSlip(cage_speed_rms=args.cage_slip, ball_rms_rad=args.ball_jitter_rad,
                       correlation_s=args.slip_correlation_s)
    bar = None

    def started(total_s):
        nonlocal bar
        args.notice_compile()
        if not args.json and total_s > LONG_RUN_S:
            from tqdm import tqdm
            bar = tqdm(total=round(total_s, 3), unit="sim s", desc="cmsim simulate",
                       file=sys.stderr, leave=False)

    def progress(done_s, total_s):
        if bar is not None:
            bar.update(round(done_s, 3) - bar.n)

    try:
        run_ = simulate(rig, op, args.duration_s, fs_hz=args.fs_hz, substeps=args.substeps,
                        mesh=mesh, slip=slip, seed=args.seed, warmup_s=args.warmup_s,
                        faults=faults, profile=profile, progress=progress, on_start=started,
                        losses=args.losses or None)
    finally:
        if bar is not None:
            bar.close()
    if machine is not None:
        healthy = None      # the same run, healthy, on the machine's rig at its op
        if machine.needs_reference(op, faults, profile, rig):
            healthy = simulate(machine.rig, machine.op, args.duration_s, fs_hz=args.fs_hz,
                               substeps=args.substeps, mesh=mesh, slip=slip, seed=args.seed,
                               warmup_s=args.warmup_s, losses=args.losses or None)
        run_ = machine.sensor_channel(run_, args.seed, healthy=healthy)
    elif args.sensors or args.sensor_noise or args.sensor_fs_hz is not None:
        from cmsim.sensors import add_sensors
        run_ = add_sensors(run_, noise_rms=args.sensor_noise, fs_hz=args.sensor_fs_hz)
    if args.out:
        run_.save(args.out)
    freqs = rig_frequencies(rig, op)
    first = rig.bearing_names[0]
    return {"shaft_hz": freqs.fr1_hz, "gmf_hz": freqs.gmf_hz,
            "bpf_hz": freqs.bearing(first).bpf_hz, **run_.summary(),
            "faults": [f["label"] for f in run_.meta["faults"]],
            "losses": _losses_summary(run_.meta.get("losses")),
            "fault_frequencies": run_.meta["fault_frequencies"],
            "speed_profile": run_.meta["speed_profile"],
            "out": str(args.out) if args.out else None}


def _losses_summary(info):
    """The ``losses`` of a run's meta for the CLI: power by source (W), total, efficiency
    (the run's power balance where there is one, else quasi-static) and the balance's
    closure, of the input power and of the losses themselves."""
    if not info:
        return None
    qs, bal = info["quasi_static"], info.get("balance")
    return {"power_w": qs["power_w"], "total_loss_w": qs["total_loss_w"],
            "efficiency": bal["efficiency"] if bal else qs["efficiency"],
            "quasi_static_efficiency": qs["efficiency"],
            "closure": bal["closure"] if bal else None,
            "closure_of_losses": bal.get("closure_of_losses") if bal else None,
            "balance_losses_w": bal["losses_w"] if bal else None}


def text(res):
    """The summary in words."""
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
