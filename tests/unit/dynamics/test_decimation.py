"""Anti-alias decimation of simulated records (issue 10: aliasing gave a false diagnosis).

Tier (a) closed form: the filter's response to pure tones (pass band, stop band from the
output Nyquist frequency on, zero phase), and a simulated record at an acquisition rate of
25.6 kHz compared line by line with the same run recorded at the integration rate.
"""

import math

import numpy as np
import pytest

import cmsim
from cmsim.dynamics import simulate
from cmsim.dynamics.decimation import AntiAliasFilter
from cmsim.errors import ParameterError
from cmsim.spectra import amplitude_spectrum

FS_OUT = 25_600.0


def _tone(aa, f_hz, n_out=4096, phase=0.3):
    n_in = 2 * aa.half_length + 1 + (n_out - 1) * aa.factor
    t = np.arange(n_in) / aa.fs_in_hz
    y = aa.apply(np.cos(2 * math.pi * f_hz * t + phase)[:, None])[:, 0]
    t_out = (aa.half_length + aa.factor * np.arange(y.size)) / aa.fs_in_hz
    return y, np.cos(2 * math.pi * f_hz * t_out + phase)


@pytest.mark.parametrize("factor", [2, 3, 38])
def test_pass_band_is_flat_and_in_phase(factor):
    aa = AntiAliasFilter(factor, FS_OUT * factor)
    for frac in (0.05, 0.4, 0.79):
        y, exact = _tone(aa, frac * 0.5 * FS_OUT)
        # flat to 1e-3 (0.01 dB) and centred: the samples are the tone at the output instants
        np.testing.assert_allclose(y, exact, atol=1.5e-3)


@pytest.mark.parametrize("factor", [2, 3, 38])
def test_everything_above_nyquist_is_at_least_60_db_down(factor):
    aa = AntiAliasFilter(factor, FS_OUT * factor)
    for frac in (1.0, 1.07, 1.5, 3.0, 0.99 * factor):
        y, _ = _tone(aa, frac * 0.5 * FS_OUT)
        assert np.max(np.abs(y)) < 1e-3, frac          # -60 dB (designed for -80 dB)


def test_filter_is_centred_on_output_instants():
    aa = AntiAliasFilter(3, 76_800.0)
    assert (aa.taps.size - 1) % (2 * aa.factor) == 0
    np.testing.assert_allclose(aa.taps, aa.taps[::-1], atol=0)       # linear phase
    assert aa.taps.sum() == pytest.approx(1.0, abs=1e-4)               # unit DC gain


def test_bad_filter_input():
    with pytest.raises(ParameterError, match="factor"):
        AntiAliasFilter(1, 1e4)
    with pytest.raises(ParameterError, match="passband"):
        AntiAliasFilter(2, 1e4, passband=1.0)


@pytest.fixture(scope="module")
def runs():
    rig = cmsim.Rig.paper_2016()
    op = cmsim.OperatingPoint(1000.0, 100.0)
    kw = dict(seed=5, cage_phases_rad=[0.3, 1.1, 2.0, 4.4], mesh="potential-energy",
              scheme="ode3")
    slow = simulate(rig, op, 0.5, fs_hz=FS_OUT, **kw)          # 3 steps per sample
    fast = simulate(rig, op, 0.5, fs_hz=3 * FS_OUT, **kw)      # the same steps, all kept
    return slow, fast


def test_record_at_acquisition_rate_has_no_aliased_lines(runs):
    """30×GMF (14 kHz, above the 12.8 kHz Nyquist frequency) would alias to 11.6 kHz, which
    is not a GMF harmonic: the 25.6 kHz record carries it ≥ 60 dB below its level in the
    full-rate record, and matches the full-rate record below 0.8 × Nyquist."""
    slow, fast = runs
    assert slow.meta["substeps"] == 3 and fast.meta["substeps"] == 1
    assert slow.meta["integration_fs_hz"] == pytest.approx(fast.meta["fs_hz"])
    gmf = 1000.0 / 60.0 * 28
    for name in ("F_1b1_loa", "dte_um"):
        s_slow = amplitude_spectrum(slow[name], slow.fs_hz)
        s_fast = amplitude_spectrum(fast[name], fast.fs_hz)

        def level(spec, f):
            i = int(np.argmin(np.abs(spec.freq_hz - f)))
            return float(spec.amplitude[max(i - 3, 0):i + 4].max())

        for k in (28, 30, 40, 50):
            f = k * gmf
            alias = FS_OUT - f if f < FS_OUT else f - FS_OUT * round(f / FS_OUT)
            alias = abs(alias)
            # the alias bin holds at most what the full-rate record has there (pass-band
            # ripple 1e-3) plus 1e-3 (-60 dB) of the line above Nyquist
            assert level(s_slow, alias) <= (1 + 1e-3) * level(s_fast, alias) \
                + 1e-3 * level(s_fast, f)
        for k in (1, 2, 5, 10, 20):                                # pass band unchanged
            assert level(s_slow, k * gmf) == pytest.approx(level(s_fast, k * gmf), rel=2e-3)


def test_decimated_record_keeps_its_time_base(runs):
    slow, fast = runs
    np.testing.assert_allclose(slow.t[:5], fast.t[:15:3], rtol=0, atol=1e-12)
    # the mean load path is unchanged by the filter (unit DC gain)
    assert np.mean(slow["F_1b1_loa"]) == pytest.approx(np.mean(fast["F_1b1_loa"]), rel=1e-4)


def test_recording_a_few_signals_gives_the_same_arrays():
    """``record=`` filters only the columns the kept signals need: the dynamics and those
    signals are the same, bit for bit, as in a full run (decimated and not)."""
    rig = cmsim.Rig.paper_2016()
    op = cmsim.OperatingPoint(1000.0, 20.0)
    keep = ("F_1b1_y", "F_2b1_loa", "dte_um", "theta_1b1", "Fmesh_total")
    for fs in (25_600.0, 75_000.0):          # decimated (3 substeps), and not
        full = simulate(rig, op, 0.05, fs_hz=fs, seed=2)
        few = simulate(rig, op, 0.05, fs_hz=fs, seed=2, record=keep)
        assert set(few.signals) == set(keep)
        assert few.meta["recorded"] == sorted(keep)
        for name in keep:
            np.testing.assert_array_equal(few[name], full[name])
    with pytest.raises(ParameterError, match="record names an unknown signal 'F_9z9_y'"):
        simulate(rig, op, 0.01, record=("F_9z9_y",))
