"""The train/val/test split of groups (:func:`cmsim.datasets.windows.split_of`) for any
groups, seeds and fractions (property tests).

Test tier: property (hypothesis). A group's split is a function of the group, the seed and
the fractions alone: the same whatever other groups there are or in what order (a dataset
that grows keeps every split), so no group's windows straddle two splits; a split of
fraction 0 is empty and one of fraction 1 takes every group; a larger train fraction only
moves groups into train.
"""

from hypothesis import given, settings
from hypothesis import strategies as st

from cmsim.datasets.windows import SPLITS, split_of, window_starts

groups = st.lists(st.text(min_size=1, max_size=12), min_size=1, max_size=40, unique=True)
seeds = st.integers(min_value=0, max_value=2 ** 32 - 1)


@st.composite
def fractions(draw):
    a = draw(st.integers(min_value=0, max_value=100))
    b = draw(st.integers(min_value=0, max_value=100 - a))
    return (a / 100, b / 100, (100 - a - b) / 100)


@settings(max_examples=200, deadline=None)
@given(groups, groups, seeds, fractions(), st.randoms())
def test_a_groups_split_does_not_depend_on_the_others(gs, more, seed, f, rnd):
    """Splits drawn over a dataset, a grown one and a shuffled one agree group by group."""
    first = {g: split_of(g, seed, f) for g in gs}
    grown = gs + [g for g in more if g not in first]
    rnd.shuffle(grown)
    again = {g: split_of(g, seed, f) for g in grown}
    assert all(again[g] == s for g, s in first.items())
    assert set(first.values()) <= set(SPLITS)


@settings(max_examples=200, deadline=None)
@given(groups, seeds, st.integers(min_value=1, max_value=50), st.integers(1, 5000),
       st.integers(1, 64), st.integers(1, 64))
def test_no_group_straddles_two_splits(gs, seed, per_group, n, window, hop):
    """Every window of a group (as many as the window rule cuts) lands in its group's one
    split."""
    windows = [(g, int(start)) for g in gs
               for start in window_starts(max(n, window), window, hop)[:per_group]]
    seen = {}
    for g, _ in windows:
        seen.setdefault(g, set()).add(split_of(g, seed))
    assert all(len(s) == 1 for s in seen.values())


@settings(max_examples=200, deadline=None)
@given(st.text(min_size=1, max_size=12), seeds, fractions(), st.integers(0, 100))
def test_empty_and_full_fractions_and_a_growing_train(g, seed, f, extra):
    for i, name in enumerate(SPLITS):
        only = tuple(1.0 if j == i else 0.0 for j in range(3))
        assert split_of(g, seed, only) == name
    bigger = min(100, round(100 * f[0]) + extra) / 100
    if split_of(g, seed, f) == "train":
        assert split_of(g, seed, (bigger, (100 - round(100 * bigger)) / 100, 0.0)) == "train"


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 2048), st.integers(1, 2048))
def test_windows_lie_inside_the_record_every_hop(n, window, hop):
    starts = window_starts(n, window, hop)
    assert all(s + window <= n for s in starts)
    assert list(starts) == list(range(0, max(0, n - window + 1), hop))
