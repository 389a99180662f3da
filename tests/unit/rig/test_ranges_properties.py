"""The one table of ranges holds for any value, and each bound is the one its users need.

Test tier: property (hypothesis) and closed form. For every entry of
:data:`cmsim.rig.RANGES` and any number: ``Range.contains``, ``Range.check`` and the command
line's parser (:func:`cmsim.cli.contract.ranged`) give one verdict, a refusal names the
parameter and the range, and an accepted value comes back unchanged. The seed's bounds are
those of the generators a seed reaches (numpy's legacy ``RandomState``, scikit-learn's
``random_state`` in ``cmsim evaluate``): a bound off by a power of two refuses a valid seed
or lets one through that crashes later.
"""

import argparse
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cmsim.cli.contract import ranged
from cmsim.errors import ParameterError
from cmsim.rig import RANGES

NAMES = sorted(RANGES)


def _values(rng):
    """Numbers around and between a range's bounds, and far beyond them."""
    finite = [b for b in (rng.lo, rng.hi) if math.isfinite(b)]
    near = st.sampled_from(finite + [math.nextafter(b, s * math.inf) for b in finite
                                     for s in (-1, 1)]) if finite else st.nothing()
    wide = st.floats(allow_nan=True, allow_infinity=True, width=64)
    between = (st.floats(min_value=rng.lo, max_value=rng.hi, allow_nan=False)
               if all(math.isfinite(b) for b in (rng.lo, rng.hi)) else wide)
    if rng.integer:
        ints = st.integers(min_value=-2 ** 40, max_value=2 ** 40)
        return st.one_of(ints, near.map(int) if finite else ints, wide)
    return st.one_of(near, between, wide)


@pytest.mark.parametrize("name", NAMES)
@settings(max_examples=150, deadline=None)
@given(data=st.data())
def test_contains_check_and_the_parser_agree_for_any_value(name, data):
    """One verdict for any value from the three readers of a range (an integer range's
    check and parser take ints only: 3.0 is refused there, 3 taken)."""
    rng = RANGES[name]
    v = data.draw(_values(rng))
    parse = ranged(rng)
    if rng.integer and isinstance(v, float):     # check takes an integer range's value as
        with pytest.raises(ParameterError):      # an int only, as the parser reads it
            rng.check(name, v)
        v = int(v) if math.isfinite(v) and v == int(v) else v
    if rng.contains(v):
        assert rng.check(name, v) == v
        if not isinstance(v, float) or math.isfinite(v):
            assert parse(repr(v) if isinstance(v, float) else str(v)) == v
    else:
        with pytest.raises(ParameterError) as err:
            rng.check(name, v)
        assert err.value.param == name and rng.allowed in str(err.value)
        with pytest.raises(argparse.ArgumentTypeError, match="must be"):
            parse(repr(v) if isinstance(v, float) else str(v))


@pytest.mark.parametrize("name", NAMES)
def test_an_open_bound_is_refused_and_a_closed_one_taken(name):
    rng = RANGES[name]
    for bound, is_open in ((rng.lo, rng.lo_open), (rng.hi, rng.hi_open)):
        if math.isfinite(bound):
            value = int(bound) if rng.integer else bound
            assert rng.contains(value) is not is_open, (name, bound)


def test_the_seed_range_is_what_the_generators_it_reaches_accept():
    """Every seed of the range seeds numpy's RandomState (and so scikit-learn's
    random_state, which ``cmsim evaluate --seed`` reaches), and the first seed past its top
    does not: the bound is exactly 2**32 - 1, not a power of two off."""
    seed = RANGES["seed"]
    assert seed.contains(0) and not seed.contains(-1)
    np.random.RandomState(int(seed.hi))
    np.random.default_rng(int(seed.hi))
    with pytest.raises(ValueError):
        np.random.RandomState(int(seed.hi) + 1)
    assert not seed.contains(int(seed.hi) + 1)
