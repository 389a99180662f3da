"""Every option reads the range of the quantity it sets, from the one table.

Test tier: structure (the option table against the range table). An option whose name is a
quantity of :data:`cmsim.rig.RANGES` (``--torque-nm`` → ``torque_nm``), or that sets one
under another name (``--sensor-fs-hz`` sets a sample rate: ``fs_hz``), must check that
quantity's range — the range itself, or one derived from it with the same bounds — never
another option's (the class of a planted bug: ``--torque-nm`` typed with
``number("speed_rpm")``; ranges of the same unit can look alike).
"""

import pytest

from cmsim.cli import contract
from cmsim.cli.app import build_parser
from cmsim.rig import RANGES

#: Options that set a quantity of the table under a name of their own: dest → quantity.
SETS = {"table_torque_nm": "torque_nm", "sensor_noise": "sensor_noise_m_s2",
        "sensor_fs_hz": "fs_hz", "ramp_to_rpm": "speed_rpm", "split_seed": "seed",
        "resample_hz": "record_fs_hz"}

#: Commands whose --fs-hz is a measured recording's rate (any rate a file may hold), not
#: the simulation's output rate.
RECORDING_COMMANDS = {"spectrum", "compare", "calibrate", "import"}


def _quantity(command, dest):
    if dest == "fs_hz" and command in RECORDING_COMMANDS:
        return "record_fs_hz"
    return SETS.get(dest, dest if dest in RANGES else None)


def _cases():
    out = []
    for command, sub in contract.subparsers(build_parser()).items():
        for a in sub._actions:
            rng = getattr(a.type, "range", None)
            key = _quantity(command, a.dest)
            if rng is not None and key is not None:
                out.append(pytest.param(command, a.dest, key, rng, id=f"{command}-{a.dest}"))
    return out


@pytest.mark.parametrize("command, dest, key, rng", _cases())
def test_an_option_checks_the_range_of_what_it_sets(command, dest, key, rng):
    want = RANGES[key]
    same = rng == want or (rng.lo == want.lo and rng.hi == want.hi and rng.unit == want.unit
                           and rng.integer == want.integer)
    assert same, (f"{command} --{dest.replace('_', '-')} checks {rng.allowed}, the range of "
                  f"{key} is {want.allowed}")


def test_the_cases_cover_the_operating_point_and_sampling_of_every_command():
    ids = {p.id for p in _cases()}
    for case in ("simulate-speed_rpm", "simulate-torque_nm", "simulate-fs_hz",
                 "simulate-sensor_fs_hz", "sweep-torque_nm", "spectrum-fs_hz",
                 "export-split_seed", "mesh-table-torque_nm"):
        assert case in ids, case
