"""The one table of ranges, :data:`cmsim.rig.RANGES`: each bound is inclusive as stated.

Test tier: (a) closed form: for every entry, the maximum (and minimum) its message states
is accepted by ``Range.check`` and ``Range.contains`` and the next number beyond it refused, with a message naming
the parameter and the range; so an off-by-one at any bound, or a message that rounds a bound
(``2π`` printed as ``6.28319``, which is above 2π), fails. The command line's copy of the rule
is tested over every option in ``tests/cli/test_contract.py``.
"""

import math
import re

import pytest

from cmsim.errors import ParameterError
from cmsim.rig import RANGES


def _stated_bounds(allowed):
    """``[(text, closed, side)]`` of the bounds a range's text states."""
    m = re.search(r" in ([\[(])([^,]+), ([^\])]+)([\])])", allowed)
    if m:
        return [(m.group(2), m.group(1) == "[", -1), (m.group(3), m.group(4) == "]", +1)]
    m = re.search(r" ([<>]=?) (\S+)", allowed)
    return [(m.group(2), m.group(1).endswith("="), +1 if "<" in m.group(1) else -1)] if m \
        else []


def _beyond(text, side, integer):
    """The next value past the bound ``text`` on ``side`` (+1 above, -1 below)."""
    if integer:
        return int(text) + side
    return math.nextafter(float(text), side * math.inf)


CASES = [(name, text, closed, side) for name, rng in RANGES.items()
         for text, closed, side in _stated_bounds(rng.allowed)]


@pytest.mark.parametrize("name, text, closed, side", CASES,
                         ids=[f"{n}-{'max' if s > 0 else 'min'}" for n, _, _, s in CASES])
def test_stated_bound_is_inclusive_as_stated(name, text, closed, side):
    rng = RANGES[name]
    bound = int(text) if rng.integer else float(text)
    if closed:
        assert rng.check(name, bound) == pytest.approx(bound, rel=1e-15)
        assert rng.contains(bound)                        # the command line's test
        refused = _beyond(text, side, rng.integer)
    else:
        refused = bound
    assert not rng.contains(refused)
    with pytest.raises(ParameterError, match=re.escape(f"{name} must be {rng.allowed}")):
        rng.check(name, refused)


def test_every_entry_states_its_upper_bound():
    """A user reads the maximum of every setting (none is unbounded above)."""
    assert {n for n, _, _, s in CASES if s > 0} == set(RANGES)
