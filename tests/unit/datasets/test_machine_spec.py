"""A dataset generated through a calibrated machine (issue 25: ``[machine]`` in a spec).

Tier (a) closed form: a machine with a known flat path and a known background line; a
record's machine channel must carry that line at its amplitude, be the model force through
the path (the same as ``simulate --machine`` makes of the same run), and the spec must refuse
what contradicts the machine (another rig, another sample rate, a missing file).
"""

import copy
import dataclasses
import hashlib
import json

import numpy as np
import pytest

from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.datasets.spec_toml import through_machine
from cmsim.diagnostics.syn2real import synthetic_windows
from cmsim.dynamics import simulate
from cmsim.errors import ParameterError
from cmsim.machine import Background, BackgroundLine, Machine, TransferPath, twin_mesh
from cmsim.rig import OperatingPoint, Rig, Rotor

#: Batched runs: the module waits for the session's one compile of the batch integrator
#: (tests/conftest.py).
pytestmark = pytest.mark.batch_kernels

FS = 12_800.0
GAIN = 0.01                     # sensor unit per N, flat
LINE = BackgroundLine("fixed", 50.0, 0.3)


def _machine():
    f = tuple(np.linspace(0.0, FS / 2, 65))
    return Machine(name="bench", rig=Rig.paper_2016(), channel="DE",
                   model_signal="accel_1b1_y", fs_hz=FS, op=OperatingPoint(1000.0, 40.0),
                   path=TransferPath("F_1b1_y", f, (GAIN,) * len(f), "g"),
                   background=Background(f, (1e-12,) * len(f), (LINE,)), unit="g")


def _spec_dict(tmp_path, **machine):
    _machine().save(tmp_path / "m.toml")
    return {"dataset": {"name": "through", "records": 4, "seed": 3},
            "operating": {"speed_rpm": 1000.0, "torque_nm": 40.0},
            "faults": {"healthy_share": 0.5,
                       "types": [{"type": "outer_race", "bearing": ["1b1"], "size_m": 1e-3,
                                  "depth_m": 1e-4}]},
            "sensor": {"duration_s": 1.0, "warmup_s": 0.02},
            "machine": {"file": "m.toml", **machine}}


def test_records_go_through_the_machine(tmp_path):
    spec = DatasetSpec.from_dict(_spec_dict(tmp_path), base_dir=tmp_path)
    assert spec.fs_hz == FS and spec.channels == ("DE", "tacho")
    assert spec.rig == Rig.paper_2016() and spec.rig_source == "machine:bench"
    assert spec.mesh == "potential-energy"       # the twin's tooth contact, as calibrated
    generate_dataset(spec, tmp_path / "ds", workers=1)
    ds = load(tmp_path / "ds")
    assert len(ds) == 4
    machine = _machine()
    healthy = 0
    for r in ds:
        x = np.asarray(r.signals["DE"], dtype=float)
        n = x.size
        assert n == int(FS)
        amp = np.abs(np.fft.rfft(x * np.hanning(n))) * 2 / np.hanning(n).sum()
        assert amp[int(round(LINE.value * n / FS))] == pytest.approx(LINE.amplitude, rel=0.05)
        if r.meta["labels"]["faults"]:
            continue
        healthy += 1
        # the healthy record is the model force through the path: what simulate --machine
        # makes of the same run
        run = simulate(Rig.paper_2016(), OperatingPoint(1000.0, 40.0), 1.0, fs_hz=FS,
                       seed=r.meta["record"]["seed"], warmup_s=0.02,
                       record=list(machine.force_signals), mesh=twin_mesh(machine.rig))
        want = machine.sensor_channel(run, r.meta["record"]["seed"])["DE"]
        np.testing.assert_allclose(x, want, atol=1e-5 * np.abs(want).max())
        force = np.asarray(run["F_1b1_y"])
        assert np.std(x - want) < 1e-3 * GAIN * np.std(force - force.mean())
    assert 1 <= healthy < len(ds)
    # sim-to-real training reads the machine's channel by default
    ws = synthetic_windows(tmp_path / "ds")
    first = np.asarray(next(iter(ds)).signals["DE"], dtype=np.float32)
    np.testing.assert_allclose(ws.x[0], first[:ws.x.shape[1]] - first[:ws.x.shape[1]].mean(),
                               atol=1e-6 * np.abs(first).max())


def test_a_spec_refuses_what_contradicts_its_machine(tmp_path):
    with pytest.raises(ParameterError, match="rig"):
        DatasetSpec.from_dict({**_spec_dict(tmp_path), "rig": {"builtin": "paper_2016"}},
                              base_dir=tmp_path)
    bad = _spec_dict(tmp_path)
    bad["sensor"]["fs_hz"] = 25_600.0
    with pytest.raises(ParameterError, match="sensor.fs_hz.*12800"):
        DatasetSpec.from_dict(bad, base_dir=tmp_path)
    with pytest.raises(ParameterError, match="machine.file"):
        DatasetSpec.from_dict({**_spec_dict(tmp_path), "machine": {"file": "nope.toml"}},
                              base_dir=tmp_path)
    with pytest.raises(ParameterError, match="machine.file"):
        DatasetSpec.from_dict({**_spec_dict(tmp_path), "machine": {}}, base_dir=tmp_path)


def test_records_default_to_the_machines_operating_point(tmp_path):
    """A spec through a machine that leaves [operating] out runs at the machine's speed and
    load (a bearing rig's radial load, a gear rig's torque), not at 1000 rpm unloaded: an
    unloaded bearing carries no force, and a labelled fault would make no signal."""
    data = _spec_dict(tmp_path)
    del data["operating"]
    spec = DatasetSpec.from_dict(data, base_dir=tmp_path)
    op = spec.record_operating_point(spec.record(0))
    assert (op.speed_rpm, op.torque_nm) == (1000.0, 40.0)
    # the Python API the same, and what a spec states still wins
    api = DatasetSpec(fixed={"torque_nm": 10.0}, records=2, sampling="random", fs_hz=FS,
                      machine=_machine(), channels=["DE"])
    op = api.record_operating_point(api.record(0))
    assert (op.speed_rpm, op.torque_nm) == (1000.0, 10.0)
    bearing = Machine.load(tmp_path / "m.toml")
    bearing_rig = Rig.rotor_on_bearings(bearing.rig.bearings[0], Rotor(3.0, 0.01))
    loaded = dataclasses.replace(bearing, rig=bearing_rig,
                                 op=OperatingPoint(1797.0, 0.0, radial_load_n=98.0))
    spec = DatasetSpec(records=1, sampling="random", fs_hz=FS, machine=loaded,
                       channels=["DE"])
    op = spec.record_operating_point(spec.record(0))
    assert (op.speed_rpm, op.radial_load_n, op.torque_nm) == (1797.0, 98.0, 0.0)


def test_through_a_machine_with_its_baseline_a_record_is_a_stretch_of_it_plus_the_change(
        tmp_path):
    """A machine that keeps its baseline (every calibrated machine): a healthy record at the
    machine's operating point is a stretch of that baseline, sample for sample (the real
    machine's own signal: what sim-to-real trains on); a faulty record is a stretch with the
    fault's change laid on it — the same stretch with a ball-pass family added (its BPFO
    line over the stretch's own), never the model force through the path."""
    from cmsim.frequencies import rig_frequencies
    from cmsim.machine.baseline import Baseline

    rng = np.random.default_rng(8)
    t = np.arange(int(3 * FS)) / FS
    own = 0.05 * rng.standard_normal(t.size) + 0.2 * np.cos(2 * np.pi * 123.0 * t)
    machine = dataclasses.replace(_machine(), baseline=Baseline((own,), FS))
    data = _spec_dict(tmp_path)
    machine.save(tmp_path / "m.toml")
    spec = DatasetSpec.from_dict(data, base_dir=tmp_path)
    assert spec.machine.baseline is not None            # the spec read the baseline back
    generate_dataset(spec, tmp_path / "ds", workers=1)
    bpfo = rig_frequencies(machine.rig, machine.op).bearing("1b1").bpfo_hz
    kinds = set()
    for r in load(tmp_path / "ds"):
        x = np.asarray(r.signals["DE"], dtype=float)
        n = x.size
        stretch = machine.baseline.piece(n, np.random.default_rng([r.meta["record"]["seed"],
                                                                    104729]))
        if not r.meta["labels"]["faults"]:
            kinds.add("healthy")
            np.testing.assert_allclose(x, stretch - stretch.mean(), atol=1e-6)
            continue
        kinds.add("fault")
        amp = np.abs(np.fft.rfft(x * np.hanning(n))) * 2 / np.hanning(n).sum()
        own_amp = np.abs(np.fft.rfft(stretch * np.hanning(n))) * 2 / np.hanning(n).sum()
        k = int(round(bpfo * n / FS))
        assert amp[k - 2:k + 3].max() > 10 * own_amp[k - 2:k + 3].max()   # +20 dB over it
        assert np.abs(amp[120:127] - own_amp[120:127]).max() < 0.1 * own_amp[120:127].max()
    assert kinds == {"healthy", "fault"}


@pytest.mark.parametrize("key, table, value", [
    ("sensor.channels[0]", "sensor", {"channels": ["accel_1b1_y", "tacho"]}),
    ("nuisances.housing_mode_hz", "nuisances", {"housing_mode_hz": 3000.0}),
    ("nuisances.sensor_noise_m_s2", "nuisances", {"sensor_noise_m_s2": 0.1})])
def test_a_machine_spec_refuses_what_the_machine_owns(tmp_path, key, table, value):
    """A [machine] added to a stock spec: the model's accelerometer channel and the housing
    and sensor-noise nuisances are the machine's own; the spec is refused naming the key
    (issue 48; a stock spec kept accel_1b1_y and its housing nuisances)."""
    data = _spec_dict(tmp_path)
    data[table] = {**data.get(table, {}), **value}
    with pytest.raises(ParameterError, match=key.replace("[", r"\[").replace("]", r"\]")):
        DatasetSpec.from_dict(data, base_dir=tmp_path)


def test_a_stock_spec_through_a_machine_is_accepted_as_the_machine_owns(tmp_path):
    """The refusal above, the other way: a stock spec with its rig, housing and sensor
    nuisances and accelerometer channel, made through a machine by
    :func:`~cmsim.datasets.spec_toml.through_machine`, is accepted, on the machine's rig and
    channel; the stock table itself is left as it was."""
    _machine().save(tmp_path / "m.toml")
    stock = {**{k: v for k, v in _spec_dict(tmp_path).items() if k != "machine"},
             "rig": {"builtin": "paper_2016"},
             "nuisances": {"housing_mode_hz": 3000.0, "sensor_noise_m_s2": 0.1,
                           "housing_damping": 0.05, "slip": 0.01},
             "sensor": {"channels": ["accel_1b1_y"], "duration_s": 1.0}}
    kept = copy.deepcopy(stock)
    spec = DatasetSpec.from_dict(through_machine(stock, "m.toml"), base_dir=tmp_path)
    assert spec.channels == ("DE", "tacho") and spec.rig_source == "machine:bench"
    assert {n for n, _ in spec.nuisances} == {"slip"}
    assert stock == kept
    by_hand = {k: v for k, v in stock.items() if k != "rig"} | {"machine": {"file": "m.toml"}}
    with pytest.raises(ParameterError, match=r"sensor\.channels\[0\]"):
        DatasetSpec.from_dict(by_hand, base_dir=tmp_path)      # only [rig] swapped: refused


def test_a_machine_spec_s_references_run_in_batches_and_keep_the_records_bits(
        tmp_path, monkeypatch):
    """Issue 49: the healthy reference runs a machine spec's faulty records are read against
    are integrated together, as the records are; a record is then the same bits in batches
    of 2 and 3, and within a float32 unit of the single-run kernel's (batch size 1, every
    run alone)."""
    from cmsim.datasets import records
    from cmsim.datasets.records import simulate_records
    from cmsim.machine.baseline import Baseline

    rng = np.random.default_rng(8)
    t = np.arange(int(2 * FS)) / FS
    own = 0.05 * rng.standard_normal(t.size) + 0.2 * np.cos(2 * np.pi * 123.0 * t)
    data = _spec_dict(tmp_path)
    dataclasses.replace(_machine(), baseline=Baseline((own,), FS)).save(tmp_path / "m.toml")
    data["dataset"]["records"] = 6
    data["sensor"] = {"duration_s": 0.1, "warmup_s": 0.02}
    spec = DatasetSpec.from_dict(data, base_dir=tmp_path)
    plans = [spec.record(i) for i in range(6)]
    faulty = sum(p.fault is not None for p in plans)
    assert 2 <= faulty < 6          # healthy records at the machine's point need none
    batched = []
    real = records.simulate_batch
    monkeypatch.setattr(records, "simulate_batch",
                        lambda setups, size=None: batched.append(len(setups)) or real(
                            setups, size))
    by_size = {b: simulate_records(spec, plans, batch_size=b) for b in (2, 3)}
    assert batched == [6, faulty, 6, faulty]          # the records, then their references
    monkeypatch.setattr(records, "simulate_batch", real)
    alone = simulate_records(spec, plans, batch_size=1)
    for k in range(6):
        a, b, c = (by_size[2][k][0], by_size[3][k][0], alone[k][0])
        for ch in a:
            np.testing.assert_array_equal(a[ch], b[ch], err_msg=ch)
            ref = np.asarray(c[ch], dtype=float)
            # float32 channels: one unit in the last place of the signal's range at most
            tol = max(np.ptp(ref), np.max(np.abs(ref))) * 2.0 ** -22
            assert np.max(np.abs(np.asarray(a[ch], dtype=float) - ref)) <= tol, ch


def test_a_record_key_is_the_hash_of_its_whole_description(tmp_path):
    """The shared fields (the machine's path, background and baseline among them) are
    encoded once per spec, not once per record; a key stays the digest of the record's
    whole description, so a dataset made before resumes on the same keys."""
    spec = DatasetSpec.from_dict(_spec_dict(tmp_path), base_dir=tmp_path)
    whole = spec.to_dict()
    for i in range(len(spec)):
        plan = spec.record(i)
        record = {"id": plan.record_id, "seed": plan.sim_seed, "params": plan.params,
                  "rig": spec.record_rig(plan).to_dict(),
                  "op": dataclasses.asdict(spec.record_operating_point(plan)),
                  "faults": [f.to_dict() for f in plan.faults],
                  **{k: whole[k] for k in ("channels", "fs_hz", "duration_s", "warmup_s",
                                           "substeps", "mesh", "losses", "machine")}}
        text = json.dumps(record, sort_keys=True, default=str)
        assert spec.record_key(plan) == hashlib.sha256(text.encode()).hexdigest()[:16]
