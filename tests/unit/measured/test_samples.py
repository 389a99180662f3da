"""A compared channel's samples: clipping is doubted, honest data are not.

Test tier: closed form (a signal held at a rail sits on one value; continuous and
finely quantised data reach their extremes once or a few times).
"""

import numpy as np
import pytest

from cmsim.measured.samples import clipping_doubt, count_doubt


def _impacts(n=120_000, seed=0):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n)
    x[::1000] += 12.0 * rng.random(n // 1000 + (n % 1000 > 0))      # impacts
    return x


def test_a_clipped_channel_is_doubted_with_its_share():
    x = np.clip(_impacts(), -2.5, 2.5)
    text = clipping_doubt(x, "DE", "r.npz")
    share = np.mean(np.abs(x) >= 2.5)
    assert text is not None and "clipped" in text
    assert f"{100 * share:.2g} %" in text


@pytest.mark.parametrize("form", ["float", "int16 at 12 bits", "int16 of a weak signal",
                                  "one rail only touched once", "a synthetic tone at fs/24"])
def test_honest_samples_are_not_doubted(form):
    x = _impacts()
    if form == "int16 at 12 bits":
        x = np.round(x / np.max(np.abs(x)) * 2047).astype(np.int16) * 0.001
    elif form == "int16 of a weak signal":                 # a few counts: extremes repeat
        x = np.round(x * 3.0).astype(np.int16) * 0.01
    elif form == "one rail only touched once":
        x = x - x.min()
    elif form == "a synthetic tone at fs/24":     # its extremes every 24 samples
        t = np.arange(x.size)
        x = 3.0 * np.sin(2 * np.pi * t / 24) + np.sin(2 * np.pi * t / 8)
    assert clipping_doubt(np.asarray(x, float), "DE", "r.npz") is None


def test_clipping_in_a_few_samples_is_left_alone_and_in_more_is_doubted():
    """Ten samples on a rail of 120 000 pass (an int16's extreme repeats by chance); a
    thousandth of them is doubted."""
    x = _impacts()
    top = np.sort(x)[-10]
    assert clipping_doubt(np.minimum(x, top), "DE", "r") is None
    top = np.sort(x)[-120]
    assert clipping_doubt(np.minimum(x, top), "DE", "r") is not None


def test_a_sample_count_other_than_the_metadata_states_is_doubted():
    """A 2-s cut (24 000 samples) of a record whose entry states 120 000 was compared with
    the entry's rate, speed and load in silence."""
    x = _impacts(24_000)
    text = count_doubt(x, 120_000, "DE", "r.npz")
    assert text is not None and "says 120000" in text and "holds 24000" in text
    assert count_doubt(x, 24_000, "DE", "r.npz") is None
    assert count_doubt(x, None, "DE", "r.npz") is None
