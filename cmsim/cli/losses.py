"""``cmsim losses``: power losses by source and the efficiency at one operating point."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cmsim.cli.contract import ranged
from cmsim.cli.options import add_mesh_options, add_rig_options, number, resolved_setup
from cmsim.cli.output import save_figure
from cmsim.rig import Range


def register(sub):
    """Add the ``losses`` parser."""
    p = sub.add_parser("losses", help="power losses by source and the efficiency",
                       description="Windage and meshing torques (paper 000 eq. 25-28), oil "
                                   "jet, Harris-Palmgren bearing torques and mixed-lubrication "
                                   "tooth friction (paper 004 eq. 21) at one operating point; "
                                   "the load sharing of the tooth pairs comes from the mesh "
                                   "model a run would use (--mesh), so the figures match "
                                   "cmsim simulate --losses.")
    p.add_argument("--speed-rpm", type=number("speed_rpm"), required=True, help="input speed, rpm")
    p.add_argument("--torque-nm", type=number("torque_nm"), required=True,
                   help="output torque, N m")
    p.add_argument("--air-pressure-pa", type=ranged(Range(0.0, 1.0e7, lo_open=True, unit="Pa")),
                   default=101325.0, help="air pressure around the gears, Pa")
    p.add_argument("--air-temperature-c", type=ranged(Range(-100.0, 500.0, unit="C")),
                   default=20.0, help="air temperature, C")
    p.add_argument("--oil-jet-kg-s", type=ranged(Range(0.0, 100.0, unit="kg/s")), default=0.0,
                   help="radial oil-jet mass flow per gear, kg/s")
    p.add_argument("--roughness-m", type=ranged(Range(0.0, 5.0e-5, lo_open=True, unit="m")),
                   help="composite RMS roughness of the teeth, m (default: the rig's)")
    p.add_argument("--plot", type=Path, metavar="FILE.png",
                   help="write the loss breakdown against speed (paper 000 Figs. 53-57)")
    add_mesh_options(p)
    add_rig_options(p, friction=False)
    p.set_defaults(func=run, text=text)


def run(args):
    """The loss breakdown (and its figure against speed)."""
    from cmsim.losses import LossSettings, operating_losses

    rig, op, (table, _) = resolved_setup(args)
    settings = LossSettings(air_pressure_pa=args.air_pressure_pa,
                            air_temperature_c=args.air_temperature_c,
                            oil_jet_kg_s=args.oil_jet_kg_s, roughness_m=args.roughness_m)
    res = operating_losses(rig, op, settings, table).to_dict()
    res["rig"] = rig.name
    res["plot"] = None
    if args.plot:
        from cmsim.losses.plots import loss_breakdown_figure
        top = max(13000.0, op.speed_rpm)
        fig = loss_breakdown_figure(rig, np.linspace(top / 13.0, top, 13), op.torque_nm,
                                    settings)
        save_figure(fig, args.plot)
        res["plot"] = str(args.plot)
    return res


def text(res):
    """The breakdown as a table."""
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
