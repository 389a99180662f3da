"""``cmsim modes``: natural frequencies of the model linearised about its quasi-static state."""

from __future__ import annotations

from cmsim.cli.contract import ranged
from cmsim.cli.options import add_mesh_options, add_rig_options, number, resolved_setup
from cmsim.rig import Range


def register(sub):
    """Add the ``modes`` parser."""
    p = sub.add_parser("modes", help="natural frequencies of the linearised model",
                       description="Linearise about the quasi-static state (bearings averaged "
                                   "over a ball-pass cycle) and solve the eigenproblem.")
    p.add_argument("--torque-nm", type=number("torque_nm"), required=True,
                   help="output torque, N m")
    p.add_argument("--speed-rpm", type=number("speed_rpm"), default=1000.0,
                   help="speed, rpm (sets the bearing-cycle instants)")
    p.add_argument("--radial-load-n", type=number("radial_load_n"), default=0.0,
                   help="static radial load on shaft 1's centre node, N (what loads the "
                        "bearings of a rig without gears; default 0)")
    p.add_argument("--positions", type=ranged(Range(4, 1000, integer=True)), default=24,
                   help="quasi-static positions averaged over a bearing cycle")
    add_mesh_options(p)
    add_rig_options(p, friction=False)
    p.set_defaults(func=run, text=text)


def run(args):
    """Modal analysis at the operating point."""
    from cmsim.dynamics.modal import check_loaded, modal_analysis

    rig, op, (table, model) = resolved_setup(args)
    check_loaded(rig, op)                  # bad input is refused before the compile notice
    args.notice_compile(integrates=False)
    res = modal_analysis(rig, op, model if model is not None else table,
                         n_positions=args.positions)
    return {"torque_nm": args.torque_nm, "radial_load_n": op.radial_load_n,
            "speed_rpm": args.speed_rpm,
            "frequencies_hz": [float(f) for f in res.frequencies_hz],
            "types": list(res.types), "details": list(res.details),
            "rotational_share": [float(x) for x in res.rotational_share],
            "mean_mesh_stiffness_n_per_m": res.mean_mesh_stiffness_n_per_m}


def text(res):
    """The mode table."""
    load = f" and a radial load of {res['radial_load_n']:g} N" if res["radial_load_n"] else ""
    lines = [f"natural frequencies at {res['torque_nm']:g} N m{load}",
             " mode  frequency_hz  type  detail"]
    for i, (f, t, d) in enumerate(zip(res["frequencies_hz"], res["types"], res["details"])):
        lines.append(f" {i + 1:4d}  {f:12.1f}  {t:4s}  {d}")
    return "\n".join(lines)
