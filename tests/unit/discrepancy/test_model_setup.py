"""What a comparison's simulation is keyed on (cmsim.discrepancy.model_setup).

Test tier: behaviour contract. A model setup's dynamics key decides whether a simulation is
run again, its chain key whether the sensor signal is made again: every field that shapes
the signal after the dynamics (``CHAIN_FIELDS``) moves the chain key and leaves the
dynamics key, and a fault moves the dynamics key.
"""

import pytest

from cmsim.discrepancy.model_setup import CHAIN_FIELDS, ModelSetup
from cmsim.faults import Eccentricity
from cmsim.rig import HousingPath, OperatingPoint, Rig

#: A value other than the default for every field of CHAIN_FIELDS.
OTHER = {"housing": HousingPath((1000.0,), (0.05,), (1.0,)), "noise_ratio": 0.5,
         "frequency_factor": 1.1, "background_gain": 2.0, "white_noise": 0.1,
         "shaft_forces": ((1, 0.1),), "background_level": 2.0, "structure": "floor",
         "lines_follow_path": False, "shaft_modulation": 3.0}


def _setup(**kw):
    return ModelSetup(rig=Rig.paper_2016(), op=OperatingPoint(1000.0, 50.0), **kw)


def test_every_chain_field_has_a_value_to_move():
    assert set(OTHER) == set(CHAIN_FIELDS)


@pytest.mark.parametrize("name", CHAIN_FIELDS)
def test_a_chain_field_moves_the_chain_key_and_leaves_the_dynamics_key(name):
    base, moved = _setup(), _setup(**{name: OTHER[name]})
    assert moved.chain_key() != base.chain_key()
    assert moved.dynamics_key() == base.dynamics_key()


def test_a_fault_moves_the_dynamics_key():
    base = _setup()
    faulty = base.with_faults(Eccentricity(gear=1, amplitude_m=2e-5))
    assert faulty.dynamics_key() != base.dynamics_key()
    assert faulty.chain_key() == base.chain_key()
