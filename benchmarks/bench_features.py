"""Speed of a comparison's features (issue 25: a comparison against a machine file reads
about a thousand segments' features; they were half its time), measured side by side.

Prints
1. the time per 0.5-s segment of :func:`cmsim.features.relative_features` on a gear and a
   bearing machine's record (the angle-domain generator's, no simulation);
   and of a machine's whole row (:func:`cmsim.machine.calibration.feature_rows` with the
   band-by-band families: what a signature library and a comparison read per segment);
2. side by side in one run: the single-FFT amplitude spectrum against
   :func:`scipy.signal.periodogram` converted to amplitude (how it was computed before
   2026-11-27), and their ratio (old / new);
3. the zero-phase band-pass of a segment, :func:`cmsim.spectra.bandpass` (its filter's
   initial conditions kept with its design) against :func:`scipy.signal.sosfiltfilt` (which
   solves them at every call; cmsim's until 2026-12-01), the same bits;
4. a segment's fourth moment as ``(x²)²`` against ``x ** 4`` (numpy's ``pow``; cmsim's
   kurtosis until 2026-12-01).

Run: ``python benchmarks/bench_features.py`` (about 30 s). Compare ratios, not absolute
times: the machines are noisy.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.signal

from cmsim.discrepancy.angle_domain import draw_machine, write_machine
from cmsim.features import segment_features
from cmsim.machine.calibration import feature_rows
from cmsim.measured import read_record
from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.envelope import _butter_sos, bandpass

SEG_S = 0.5
REPEATS = 5


def _record(kind):
    with tempfile.TemporaryDirectory() as tmp:
        write_machine(tmp, draw_machine(1001, kind), [("baseline", None, 0.0, 1)],
                      duration_s=5.0)
        return read_record(Path(tmp) / "baseline.npz")


def _best(fn, repeats=REPEATS):
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return min(out)


def _periodogram_amplitude(x, fs):
    _, p = scipy.signal.periodogram(x, fs, window="hann", detrend="constant",
                                    scaling="spectrum")
    amp = np.sqrt(2.0 * p)
    amp[0] = np.sqrt(p[0])
    return amp


def main():
    print("1. relative_features per 0.5-s segment")
    for kind in ("gear", "bearing"):
        rec = _record(kind)
        x = rec.signal * rec.unit_scale
        freqs = rec.model_frequencies()
        bearings = list(rec.rig.bearing_names)
        n_seg = int(x.size / rec.fs_hz / SEG_S)
        t = _best(lambda: segment_features(x, rec.fs_hz, freqs, bearings, SEG_S), 2)
        print(f"   {kind:8s} machine (fs {rec.fs_hz:.0f} Hz): {1e3 * t / n_seg:.1f} ms per "
              f"segment ({n_seg} segments)")
        n = int(SEG_S * rec.fs_hz)
        segs = x[: n_seg * n].reshape(n_seg, n)
        t = _best(lambda: feature_rows(segs, rec.fs_hz, freqs, bearings, 1.0, bands=True), 2)
        print(f"   {'':8s} a machine's row (the band-by-band families too): "
              f"{1e3 * t / n_seg:.1f} ms per segment")
    rec = _record("gear")
    fs = rec.fs_hz
    seg = rec.signal[: int(SEG_S * fs)] * rec.unit_scale
    n = 200
    old = _best(lambda: [_periodogram_amplitude(seg, fs) for _ in range(n)])
    new = _best(lambda: [amplitude_spectrum(seg, fs, window="hann") for _ in range(n)])
    print(f"2. amplitude spectrum of a segment: periodogram {1e6 * old / n:.0f} us, single "
          f"FFT {1e6 * new / n:.0f} us, ratio {old / new:.1f}")
    band = (0.1 * fs, 0.2 * fs)
    sos = _butter_sos(4, *band, fs)[0]
    same = np.array_equal(scipy.signal.sosfiltfilt(sos, seg), bandpass(seg, fs, band))
    old = _best(lambda: [scipy.signal.sosfiltfilt(sos, seg) for _ in range(n)])
    new = _best(lambda: [bandpass(seg, fs, band) for _ in range(n)])
    print(f"3. zero-phase band-pass of a segment: sosfiltfilt {1e6 * old / n:.0f} us, initial "
          f"conditions kept {1e6 * new / n:.0f} us, ratio {old / new:.1f} (the same bits: "
          f"{same})")
    d = seg - seg.mean()
    old = _best(lambda: [np.mean(d ** 4) for _ in range(n)])
    new = _best(lambda: [np.mean(np.square(d * d)) for _ in range(n)])
    print(f"4. fourth moment of a segment: x ** 4 {1e6 * old / n:.0f} us, (x²)² "
          f"{1e6 * new / n:.0f} us, ratio {old / new:.1f}")


if __name__ == "__main__":
    main()
