"""Figures: each plotting function returns a Figure with unit-bearing axis labels.

Test tier: closed form (structural checks of the figures, Agg backend, no display).
"""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from cmsim.errors import ParameterError  # noqa: E402
from cmsim.spectra import (amplitude_spectrum, kurtogram, label_peaks, plot_kurtogram,  # noqa: E402
                           plot_orbit, plot_spectrum, plot_waterfall)

FS = 10_000.0
FAM = {"GMF": 466.67, "BPF": 60.6, "fr": 1000 / 60}


def _am(depth=0.3, seconds=1.0, seed=0):
    t = np.arange(int(FS * seconds)) / FS
    rng = np.random.default_rng(seed)
    return ((1 + depth * np.cos(2 * np.pi * 60.6 * t)) * np.sin(2 * np.pi * 466.67 * t)
            + 1e-3 * rng.standard_normal(t.size))


def test_plot_spectrum_marks_families_and_labels(tmp_path):
    f, a = amplitude_spectrum(_am(), FS)
    peaks = label_peaks(f, a, FAM)
    fig = plot_spectrum(f, a, peaks, FAM, amplitude_unit="m/s²", max_freq=2000.0)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert "[Hz]" in ax.get_xlabel()
    assert "[m/s²]" in ax.get_ylabel()
    assert ax.get_yscale() == "log"
    texts = {t.get_text() for t in ax.texts}
    assert {"1GMF", "1GMF+1BPF", "1GMF-1BPF"} <= texts
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "GMF" in legend and "BPF" in legend
    fig.savefig(tmp_path / "spectrum.png")
    assert (tmp_path / "spectrum.png").stat().st_size > 1000
    lin = plot_spectrum(f, a, log=False, freq_unit="order")
    assert "Order" in lin.axes[0].get_xlabel() and lin.axes[0].get_yscale() == "linear"


@pytest.mark.parametrize("style", ["offset", "3d"])
def test_plot_waterfall(style):
    torques = [10.0, 50.0, 100.0]
    spectra = [amplitude_spectrum(_am(depth=d, seed=i), FS)
               for i, d in enumerate((0.3, 0.2, 0.1))]
    fig = plot_waterfall(spectra[0].freq_hz, [s.amplitude for s in spectra], torques,
                         style=style, max_freq=1500.0)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert "[Hz]" in ax.get_xlabel()
    assert "dB" in ax.get_ylabel() or "[N m]" in ax.get_ylabel()
    if style == "3d":
        assert ax.get_ylabel() == "Torque [N m]" and "dB" in ax.get_zlabel()
    else:
        assert len(ax.lines) == 3
        assert {"10", "50", "100"} <= {t.get_text().strip() for t in ax.texts}


def test_plot_orbit_in_micrometres_with_clearance_circle():
    phi = np.linspace(0, 4 * np.pi, 500)
    x, y = 10e-6 * np.cos(phi), 6e-6 * np.sin(phi)
    fig = plot_orbit(x, y, clearance_m=15e-6)
    ax = fig.axes[0]
    assert "[µm]" in ax.get_xlabel() and "[µm]" in ax.get_ylabel()
    xs = ax.lines[0].get_xdata()
    assert np.max(np.abs(xs)) == pytest.approx(10.0, rel=1e-6)       # plotted in µm
    circle = [ln for ln in ax.lines if ln.get_linestyle() == "--"]
    assert len(circle) == 1
    assert np.max(circle[0].get_xdata()) == pytest.approx(15.0, rel=1e-6)


def test_plot_kurtogram():
    rng = np.random.default_rng(2)
    x = rng.standard_normal(20_000)
    x[::500] += 20.0
    kg = kurtogram(x, FS)
    fig = plot_kurtogram(kg, n_freq=256)
    ax = fig.axes[0]
    assert "[Hz]" in ax.get_xlabel() and "[Hz]" in ax.get_ylabel()
    # the map shows the kurtogram's own values: one row per level, each frequency sample
    # holding the spectral kurtosis of the bin it falls in (negative values clipped to 0)
    (mesh,) = ax.collections
    image = np.asarray(mesh.get_array()).reshape(len(kg.nperseg), 256)
    grid = np.linspace(0.0, FS / 2, 256)
    for row, f, sk in zip(image, kg.freq_hz, kg.kurtosis):
        nearest = np.abs(f[None, :] - grid[:, None]).argmin(axis=1)
        np.testing.assert_allclose(row, np.clip(np.nan_to_num(sk[nearest]), 0.0, None),
                                   rtol=1e-12)
    assert image.max() == pytest.approx(kg.kurtosis_max, rel=0.2)
    assert kg.kurtosis_max > 5.0                    # impulses: strongly non-Gaussian
    # the best band is drawn where the kurtogram found it, on its level's row
    (line,) = [ln for ln in ax.get_lines() if ln.get_label() == "best band"]
    np.testing.assert_allclose(line.get_xdata(), kg.band_hz, rtol=1e-12)
    assert list(line.get_ydata()) == [kg.nperseg.index(kg.best_nperseg)] * 2
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert labels == [f"{kg.bandwidth_of(n):.0f}" for n in kg.nperseg]


@pytest.mark.parametrize("call, name", [
    (lambda: plot_waterfall(np.arange(10.0), [np.ones(10)], [1.0], style="surface"), "style"),
    (lambda: plot_waterfall(np.arange(10.0), [np.ones(10)], [1.0, 2.0]), "values"),
    (lambda: plot_orbit(np.ones(10), np.ones(10), clearance_m=np.nan), "clearance_m"),
    (lambda: plot_spectrum(np.arange(10.0), np.ones(9)), "freq"),
])
def test_bad_inputs_name_the_parameter(call, name):
    with pytest.raises(ParameterError, match=name):
        call()
