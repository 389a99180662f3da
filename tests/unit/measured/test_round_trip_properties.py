"""Any signals cmsim writes read back the same, in every format (property tests).

Test tier: property (hypothesis). For random channels (names, count, length, values), sample
rates and units of the unit table, :func:`cmsim.measured.readers.write_signals` then
:func:`~cmsim.measured.readers.read_file` gives back the same channels in order, the same
samples (exactly, or to float32 at full scale for a WAV), the rate and every unit. Rates are
whole numbers of Hz in every format (what DAQs write; a WAV header holds no more), of at most
5 significant digits in a UFF file (its abscissa increment is printed with 6: 999999 Hz and
1 MHz print alike), any positive number in the formats that store a float.
"""

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cmsim.measured.readers import read_file, write_signals
from cmsim.measured.readers._common import TIME_NAME
from cmsim.measured.schema import known_units

RESERVED = {"t", "time", "meta", "source", "fs_hz", "units", "fs", "sample_rate",
            "samplerate", "sampling_rate"}

names = st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,11}", fullmatch=True).filter(
    lambda s: s.lower() not in RESERVED and not TIME_NAME.match(s)
    and not s.lower().endswith("rpm"))


@st.composite
def records(draw, whole_rate, digits=None):
    chans = draw(st.lists(names, min_size=1, max_size=4, unique_by=str.lower))
    n = draw(st.integers(min_value=16, max_value=256))
    values = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, width=64)
    signals = {c: np.array(draw(st.lists(values, min_size=n, max_size=n))) for c in chans}
    for c in chans:                             # never a constant or all-zero channel
        signals[c][0] += 1.0
    rate = (float(draw(st.integers(min_value=1000, max_value=999_999))) if whole_rate else
            draw(st.floats(min_value=1.0, max_value=1e7, allow_nan=False)))
    if digits is not None:
        rate = float(f"{rate:.{digits}g}")
    units = {c: draw(st.sampled_from(known_units() + (None,))) for c in chans}
    return signals, rate, units


def _round_trip(suffix, signals, rate, units):
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / f"r{suffix}"
        write_signals(path, signals, rate, units)
        f = read_file(path)
    assert list(f.signals) == list(signals), (list(f.signals), list(signals))
    for c, x in signals.items():
        if suffix == ".wav":                    # float32 at full scale
            peak = max(float(np.max(np.abs(v))) for v in signals.values())
            np.testing.assert_allclose(f.signals[c], x, rtol=0, atol=2e-7 * peak)
        else:
            np.testing.assert_array_equal(f.signals[c], x)
    assert f.rate_hz == pytest.approx(rate, rel=1e-11), (f.rate_hz, rate)   # a CSV's time
    # stamps give the rate to 12 significant digits (others' files print fewer)
    assert {c: u for c, u in f.units.items()} == {c: u for c, u in units.items() if u}


SETTINGS = settings(max_examples=25, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@pytest.mark.parametrize("suffix", [".npz", ".csv", ".wav", ".mat", ".uff", ".tdms"])
@SETTINGS
@given(data=st.data())
def test_whole_rates_round_trip_in_every_format(suffix, data):
    if suffix == ".uff":
        pytest.importorskip("pyuff")
    if suffix == ".tdms":
        pytest.importorskip("nptdms")
    _round_trip(suffix, *data.draw(records(True, 5 if suffix == ".uff" else None)))


@pytest.mark.parametrize("suffix", [".npz", ".mat", ".tdms", ".csv"])
@SETTINGS
@given(data=st.data())
def test_any_rate_round_trips_where_the_format_stores_a_float(suffix, data):
    if suffix == ".tdms":
        pytest.importorskip("nptdms")
    signals, rate, units = data.draw(records(False))
    assert math.isfinite(rate)
    _round_trip(suffix, signals, rate, units)
