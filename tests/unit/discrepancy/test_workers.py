"""A comparison made by several processes (issue 25's speed): the model's runs of a setup are
dealt out by seed to helper processes; the comparison must not change with their number.

Tier: equality against the one-process comparison (every number of the result), on a record
whose nominal model is the documented path (the healthy level the sensor noise refers to is
read first, then shared), with a budget that runs out during the ranking, so that the
budget's accounting is checked too (a run made by a helper is counted once, where one
process counts it); and a machine's signature library, whose entries are dealt out to
worker processes.
"""

import json
import os

import pytest

from cmsim.discrepancy import compare
from cmsim.discrepancy.causes import ModelSetup
from cmsim.discrepancy import evaluator
from cmsim.discrepancy.evaluator import Evaluator
from cmsim.discrepancy.synthetic import hidden_effect_record
from cmsim.machine import calibrate


def _same(a, b):
    da, db = a.to_dict(), b.to_dict()
    for d in (da, db):
        d.pop("wall_s")
    assert json.dumps(da, default=float) == json.dumps(db, default=float)
    assert a.simulations == b.simulations


@pytest.mark.slow
def test_documented_path_comparison_is_the_same_on_two_processes():
    record = hidden_effect_record("bearing_inner_race", 1003, duration_s=2.0).record
    one = compare(record, budget=24, workers=1)
    two = compare(record, budget=24, workers=2)
    _same(one, two)
    # the ranking spent its whole share (24 − 4), the held-out runs of the nominal model 2
    assert one.simulations == 24 - 4 + 2


@pytest.mark.slow
def test_a_signature_library_is_the_same_on_one_and_two_processes():
    """The library's entries are dealt out to worker processes: the same tables, bit for
    bit, as one process makes."""
    import numpy as np

    from cmsim.discrepancy import CAUSES
    from cmsim.discrepancy.signatures import build_library

    baseline = hidden_effect_record(None, 4, sim_seed=9, duration_s=2.0).record
    machine = calibrate([baseline], seed=4)
    causes = [CAUSES[c]() for c in ("bearing_outer_race", "noise", "unbalance")]
    one = build_library(machine, causes=causes, n_sizes=3, seed=2, workers=1)
    two = build_library(machine, causes=causes, n_sizes=3, seed=2, workers=2)
    assert one.names == two.names
    assert np.array_equal(one.realisation, two.realisation, equal_nan=True)
    assert [(e.cause, e.component, e.variant) for e in one.entries] == \
        [(e.cause, e.component, e.variant) for e in two.entries]
    for a, b in zip(one.entries, two.entries):
        assert np.array_equal(a.features, b.features, equal_nan=True)


def test_helpers_stop_with_the_evaluator_and_runs_are_counted_once():
    """The seeds of a setup are dealt out (odd places to the helper), its runs counted once;
    the helper is stopped on leaving the ``with`` block, and one process gives the same
    features."""
    record = hidden_effect_record(None, 5, duration_s=1.0).record
    setup = ModelSetup(rig=record.rig, op=record.op, housing=record.rig.housing)
    with Evaluator(record, 0.25, 0, 10, workers=2) as ev:
        rows = ev.rows(setup, ev.seeds(3))
        assert ev.count == 3 and len(ev._helpers) == 1
        pool = ev._helpers[1]
        again = ev.features(setup, ev.seeds(2))       # cached: no new run
        assert ev.count == 3
    assert ev._helpers is None
    with pytest.raises(RuntimeError):                 # the helper's pool was shut down
        pool.submit(int)
    alone = Evaluator(record, 0.25, 0, 10)
    assert alone.rows(setup, alone.seeds(3)) == rows
    assert alone.features(setup, alone.seeds(2)) == again


def _die(*args):
    os._exit(1)                                       # a helper killed mid-run


def test_a_dead_helper_leaves_its_runs_to_this_process(monkeypatch):
    record = hidden_effect_record(None, 5, duration_s=1.0).record
    setup = ModelSetup(rig=record.rig, op=record.op, housing=record.rig.housing)
    alone = Evaluator(record, 0.25, 0, 10)
    expected = alone.rows(setup, alone.seeds(2))
    monkeypatch.setattr(evaluator, "_helper_rows", _die)
    with Evaluator(record, 0.25, 0, 10, workers=2) as ev:
        assert ev.rows(setup, ev.seeds(2)) == expected
        assert ev.workers == 1 and ev._helpers is None and ev.count == 2


@pytest.mark.slow
def test_a_machine_comparison_refines_on_two_threads_as_on_one(monkeypatch):
    """Against a machine, the refining runs (the healthy and the changed model) go side by
    side on two threads where the comparison has two workers: the same comparison, number for
    number, as one thread makes, and the runs were made on two threads."""
    import threading

    from cmsim.discrepancy import CAUSES, signatures
    from cmsim.discrepancy.signatures import build_library

    baseline = hidden_effect_record(None, 4, sim_seed=9, duration_s=2.0).record
    machine = calibrate([baseline], seed=4)
    machine = machine.with_library(build_library(
        machine, causes=[CAUSES[c]() for c in ("bearing_outer_race", "unbalance")], n_sizes=3,
        seed=2, workers=1))
    record = hidden_effect_record("bearing_outer_race", 5, duration_s=2.0).record
    threads = []
    force = signatures.model_force

    def counted(*args, **kwargs):
        threads.append(threading.get_ident())
        return force(*args, **kwargs)

    monkeypatch.setattr(signatures, "model_force", counted)
    one = compare(record, machine=machine, workers=1)
    assert one.finding == "bearing_outer_race" and one.simulations == 1
    assert len(threads) == 2 and len(set(threads)) == 1
    threads.clear()
    two = compare(record, machine=machine, workers=2)
    assert len(threads) == 2 and len(set(threads)) == 2
    _same(one, two)


@pytest.mark.parametrize("floor", [False, True])
def test_a_kept_path_and_noise_draw_give_the_chains_samples_bit_for_bit(floor):
    """The evaluator keeps a run's path signal and each seed's noise draw and scales the draw
    by each noise ratio: the sensor signal is, bit for bit, what the whole chain makes of the
    run (the record's floor's coloured noise, or a share of the healthy level's white)."""
    import dataclasses

    import numpy as np

    record = hidden_effect_record(None, 5, duration_s=1.0).record
    setup = ModelSetup(rig=record.rig, op=record.op, housing=record.rig.housing)
    ev = Evaluator(record, 0.25, 0, 10, floor=record.signal if floor else None)
    first = ev.signal(setup, 0)
    for ratio in (0.02, 0.3, 2.0):
        st = dataclasses.replace(setup, noise_ratio=ratio)
        for seed in (0, 7777):
            chain = evaluator._chain(st, *ev._forces(st, seed), ev.fs, seed, ev.ref_rms,
                                     ev.floor, bearing=ev.sensor_bearing)
            assert np.array_equal(ev.signal(st, seed), chain)
    assert len(ev._paths) == 2 and len(ev._draws) == 2     # one path a run, one draw a seed
    assert np.array_equal(ev.signal(setup, 0), first)
