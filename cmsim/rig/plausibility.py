"""Loads far beyond what a rig's steel gears or ball bearings carry.

Such a run still integrates, but its results are not physical; front ends show these
warnings beside the result (the command line on stderr, or in its JSON ``warnings``). The
messages name the operating-point field (``torque_nm``, ``radial_load_n``) so a front end can
name its own option instead.
"""

from __future__ import annotations

__all__ = ["load_warnings", "PLAUSIBLE_CONTACT_STRESS_PA"]

#: ISO 6336-5 allowable contact stress of through-hardened steel is ~1500 MPa (case-hardened
#: up to ~1650); a nominal stress above twice that is far beyond what steel gears carry, Pa.
PLAUSIBLE_CONTACT_STRESS_PA = 2 * 1500e6


def load_warnings(rig, op):
    """Warnings about loads of ``op`` beyond what ``rig`` can carry (empty when plausible).

    Parameters
    ----------
    rig : Rig
        The rig.
    op : OperatingPoint
        The operating point (its largest torque or radial load, for a sweep).

    Returns
    -------
    list of str

    Examples
    --------
    >>> from cmsim.rig import OperatingPoint, Rig
    >>> load_warnings(Rig.paper_2016(), OperatingPoint(1000.0, torque_nm=100.0))
    []
    >>> len(load_warnings(Rig.paper_2016(), OperatingPoint(1000.0, torque_nm=1000.0)))
    1
    """
    found = []
    if rig.gears is not None and op.torque_nm > 0:
        sigma = rig.gears.nominal_contact_stress_pa(op.torque_nm)
        if sigma > PLAUSIBLE_CONTACT_STRESS_PA:
            found.append(
                f"torque_nm {op.torque_nm:g} gives a nominal contact stress of "
                f"{sigma / 1e6:.0f} MPa on a {1e3 * rig.gears.driving.face_width_m:g} mm face "
                f"(ISO 6336); steel gears carry about 1500 MPa (results far above "
                f"{PLAUSIBLE_CONTACT_STRESS_PA / 1e6:.0f} MPa are not physical)")
    if rig.gears is None:
        if op.torque_nm != 0:
            found.append(f"torque_nm {op.torque_nm:g} N m has no effect on a rig without "
                         f"gears: no mesh carries it (its bearings are loaded by "
                         f"radial_load_n)")
        c0 = rig.bearings[0].static_load_rating_n
        if op.radial_load_n == 0:
            found.append("a bearing rig without radial_load_n: the bearings carry no load and "
                         "every bearing force is zero")
        elif op.radial_load_n > 2 * c0:
            found.append(f"radial_load_n {op.radial_load_n:g} N is more than twice the static "
                         f"load rating C0 ~ {c0:.0f} N of bearing 1b1 (ISO 76)")
    return found
