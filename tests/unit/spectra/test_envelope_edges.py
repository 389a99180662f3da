"""Envelope analysis with band edges at 0 Hz and at the Nyquist frequency.

Tier (a) closed form. The kurtogram can pick a band that ends at fs/2, and a band starting at
0 Hz is a low-pass: :func:`~cmsim.spectra.envelope.bandpass` takes a separate branch for
each. The test signal is a strong low-frequency gear tone plus a weak high-frequency carrier
amplitude-modulated at a defect rate, as in a bearing record: demodulated in the band that
holds only the carrier, the envelope spectrum must peak at the defect rate with the
modulation's amplitude m·A, not at the gear tone.
"""

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.spectra.envelope import bandpass, envelope, envelope_spectrum

FS = 20_000.0
N = 40_000
T = np.arange(N) / FS
GEAR_HZ, GEAR_AMP = 460.0, 10.0
CARRIER_HZ, CARRIER_AMP, DEFECT_HZ, DEPTH = 8_000.0, 1.0, 105.0, 0.5
GEAR = GEAR_AMP * np.sin(2 * np.pi * GEAR_HZ * T)
BEARING = CARRIER_AMP * (1 + DEPTH * np.cos(2 * np.pi * DEFECT_HZ * T)) * np.sin(
    2 * np.pi * CARRIER_HZ * T)
X = GEAR + BEARING


def _rms(x):
    trim = x[N // 10: -N // 10]                      # away from the filter's end transients
    return float(np.sqrt(np.mean(trim ** 2)))


def _peak(spec, lo_hz=20.0):
    f, a = spec
    keep = f > lo_hz
    i = np.argmax(a[keep])
    return f[keep][i], a[keep][i]


@pytest.mark.parametrize("lo", [6_000.0, 4_000.0])
def test_band_up_to_nyquist_is_a_high_pass(lo):
    y = bandpass(X, FS, (lo, FS / 2))
    assert _rms(y - BEARING) < 0.02 * _rms(BEARING)            # the carrier passes unchanged
    assert _rms(bandpass(GEAR, FS, (lo, FS / 2))) < 1e-4 * _rms(GEAR)


@pytest.mark.parametrize("hi", [2_000.0, 5_000.0])
def test_band_from_zero_is_a_low_pass(hi):
    y = bandpass(X, FS, (0.0, hi))
    assert _rms(y - GEAR) < 1e-3 * _rms(GEAR)
    assert _rms(bandpass(BEARING, FS, (0.0, hi))) < 1e-3 * _rms(BEARING)


def test_full_band_is_the_identity_and_an_inner_band_a_band_pass():
    np.testing.assert_array_equal(bandpass(X, FS, (0.0, FS / 2)), X)
    y = bandpass(X, FS, (6_000.0, 9_500.0))
    assert _rms(y - BEARING) < 0.05 * _rms(BEARING)


@pytest.mark.parametrize("band", [(6_000.0, FS / 2), (6_000.0, 9_500.0)],
                         ids=["to-nyquist", "inner"])
def test_envelope_spectrum_peaks_at_the_defect_rate(band):
    f, a = _peak(envelope_spectrum(X, FS, band))
    assert f == pytest.approx(DEFECT_HZ, abs=FS / N)
    assert a == pytest.approx(DEPTH * CARRIER_AMP, rel=0.05)


def test_whole_band_envelope_is_dominated_by_the_gear_tone():
    """Without demodulation the defect is hidden: the reason the band matters."""
    env = envelope(X, FS)
    f, a = _peak(envelope_spectrum(X, FS))
    assert abs(f - DEFECT_HZ) > 5.0
    assert env.mean() > 5 * CARRIER_AMP


@pytest.mark.parametrize("band", [(-1.0, 100.0), (100.0, FS / 2 + 1.0), (500.0, 500.0)])
def test_bands_beyond_the_edges_are_refused(band):
    with pytest.raises(ParameterError, match="fs/2"):
        bandpass(X, FS, band)
