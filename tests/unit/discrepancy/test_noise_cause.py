"""The ``noise`` and ``background`` causes through a calibrated machine (issues 25, 16).

Tier: closed form — the machine's background is a coloured noise of known RMS confined
under 1 kHz, and its baseline that background alone. The noise cause adds white noise to
the background as calibrated, so the record's RMS is the cause's ratio over the nominal one
times the background's, and all it adds reaches the bands the baseline's background leaves
empty (a scaled background cannot change the spectrum's shape); a cause that only adds noise
cannot make the baseline quieter.
The ``background`` cause scales the machine's whole background and keeps its shape.
"""

import math

import numpy as np
import pytest

from cmsim.discrepancy.causes import (CAUSES, MACHINE_BACKGROUND_SPREAD, NOMINAL_NOISE_RATIO,
                                      ModelSetup)
from cmsim.discrepancy.signatures import change_of
from cmsim.errors import ParameterError
from cmsim.machine import Background, Machine, TransferPath
from cmsim.machine.change import apply_change
from cmsim.rig import OperatingPoint, Rig

FS = 10_000.0
N = 20_000


def _machine():
    rig = Rig.paper_2016()
    f = np.linspace(0.0, FS / 2, 501)
    psd = np.where(f <= 1000.0, 2e-4, 0.0)                     # 0.2 g² in all: RMS 0.447
    m = Machine("m", rig, "acc", "accel_1b1_y", FS, OperatingPoint(1500.0, 50.0),
                TransferPath("F_1b1_y", (0.0, FS / 2), (1e-12, 1e-12), "g"),
                Background(tuple(f), tuple(psd)))
    baseline = np.array([m.background.noise(N, FS, np.random.default_rng(i)) for i in range(6)])
    return m, ModelSetup(rig=rig, op=m.op, machine=m), baseline


def _record(setup, nominal, m, baseline):
    def no_run(_):
        raise AssertionError("the noise and background causes need no simulation")
    change = change_of(setup, nominal, no_run, FS, 0)
    return apply_change(m, baseline, change, np.random.default_rng(7))


@pytest.mark.parametrize("factor", [1.0, MACHINE_BACKGROUND_SPREAD, 2.5, 6.0])
def test_the_noise_cause_sets_the_total_rms_with_white_noise_alone(factor):
    m, nominal, baseline = _machine()
    setup = CAUSES["noise"]().apply(nominal, NOMINAL_NOISE_RATIO * factor, None)
    y = _record(setup, nominal, m, baseline)
    bg = m.background.noise_rms(FS)
    assert bg == pytest.approx(math.sqrt(0.2), rel=0.01)
    assert float(np.std(y)) == pytest.approx(factor * bg, rel=0.02)
    spec = np.sum(np.abs(np.fft.rfft(y, axis=1)) ** 2, axis=0)
    f = np.fft.rfftfreq(N, 1.0 / FS)
    high = float(np.sum(spec[f > 1100.0]) / np.sum(spec))
    white = factor ** 2 - 1.0               # what it adds to the background's power (1)
    # the white part spreads evenly to the Nyquist frequency: 0.78 of it above 1.1 kHz
    assert high == pytest.approx(white / factor ** 2 * (1.0 - 1100.0 / (FS / 2)), abs=0.01)


def test_less_noise_than_the_baseline_s_leaves_the_baseline():
    """A noise cause under the nominal ratio would take noise away: it only adds."""
    m, nominal, baseline = _machine()
    setup = CAUSES["noise"]().apply(nominal, 0.5 * NOMINAL_NOISE_RATIO, None)
    assert np.allclose(_record(setup, nominal, m, baseline), baseline, atol=1e-12)


@pytest.mark.parametrize("factor", [3.0, 30.0])
def test_the_background_cause_scales_the_machine_s_background_and_keeps_its_shape(factor):
    m, nominal, baseline = _machine()
    setup = CAUSES["background"]().apply(nominal, factor, None)
    assert setup.dynamics_key() == nominal.dynamics_key()      # no new simulation
    y = _record(setup, nominal, m, baseline)
    assert float(np.std(y)) == pytest.approx(factor * m.background.noise_rms(FS), rel=0.03)
    spec = np.sum(np.abs(np.fft.rfft(y, axis=1)) ** 2, axis=0)
    f = np.fft.rfftfreq(N, 1.0 / FS)
    assert float(np.sum(spec[f > 1100.0]) / np.sum(spec)) < 1e-3   # nothing beyond its band
    with pytest.raises(ParameterError):                  # no machine: nothing to scale
        CAUSES["background"]().apply(ModelSetup(rig=m.rig, op=m.op), factor, None)
