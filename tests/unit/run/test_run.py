"""The shared run record: signal schema, source, typed accessors, variants, save/load, summary.

Tier: closed form (a sine's mean and RMS) and structure (schema of a simulated paper-rig run,
exact round trips through the ``.npz`` file).
"""

import math

import numpy as np
import pytest

from cmsim._io import atomic_savez
from cmsim.dynamics import simulate
from cmsim.errors import ParameterError
from cmsim.rig import OperatingPoint, Rig
from cmsim.run import SIGNAL_QUANTITIES, Run, SignalInfo, signal_info


@pytest.fixture(scope="module")
def paper_run():
    """A few samples of the paper rig at 1000 rpm, 10 N·m (every signal a simulation writes)."""
    return simulate(Rig.paper_2016(), OperatingPoint(1000.0, 10.0), 2e-3, warmup_s=0.0, seed=3)


def measured(n=1000, fs_hz=10_000.0):
    t = np.arange(n) / fs_hz
    return Run(t, {"accel_1b1_x": np.sin(2 * math.pi * 500.0 * t),
                   "tacho": (np.arange(n) % 100 == 0).astype(float)},
               {"fs_hz": fs_hz, "sensor": "ICP 100 mV/g"}, source="measured")


@pytest.mark.parametrize("name, info", [
    ("F_1b1_loa", SignalInfo("force", "N", "1b1", "loa")),
    ("F_2b2_y", SignalInfo("force", "N", "2b2", "y")),
    ("dte", SignalInfo("transmission_error", "rad", "mesh", None)),
    ("dte_um", SignalInfo("transmission_error", "µm", "mesh", "loa")),
    ("Fmesh_2", SignalInfo("force", "N", "slot2", "loa")),
    ("Fmesh_total", SignalInfo("force", "N", "mesh", "loa")),
    ("x_1G1", SignalInfo("displacement", "m", "1G1", "x")),
    ("y_1D1", SignalInfo("displacement", "m", "1D1", "y")),
    ("theta_2J2", SignalInfo("rotation", "rad", "2J2", "theta")),
    ("accel_2b1_y", SignalInfo("acceleration", "m/s²", "2b1", "y")),
    ("tacho", SignalInfo("tacho", "V", "shaft1", None)),
])
def test_signal_info(name, info):
    assert signal_info(name) == info


@pytest.mark.parametrize("name", ["F_1G1_x", "F_1b1_z", "accel_1b1_loa", "dte_mm", "x_1b1_",
                                  "mic", ""])
def test_names_outside_the_schema_are_rejected(name):
    with pytest.raises(ParameterError, match="not in the run schema"):
        signal_info(name)


def test_every_signal_of_a_simulated_run_is_in_the_schema(paper_run):
    schema = paper_run.schema()
    assert set(schema) == set(paper_run.signals)
    assert {i.quantity for i in schema.values()} <= set(SIGNAL_QUANTITIES)
    assert {"dte", "dte_um", "F_1b1_loa", "Fmesh_total", "theta_2J2"} <= set(schema)
    assert schema["F_2b1_oloa"].component == "2b1"


def test_a_simulation_is_simulated_and_knows_its_rig_and_operating_point(paper_run):
    assert paper_run.source == "simulated"
    assert paper_run.rig == Rig.paper_2016()          # exact: to_dict/from_dict round trip
    assert paper_run.operating_point == OperatingPoint(1000.0, 10.0)


def test_a_record_without_rig_has_none():
    run = measured()
    assert run.rig is None and run.operating_point is None


def test_bad_operating_point_meta_names_the_field():
    run = measured().with_meta(operating_point={"speed": 1000.0})
    with pytest.raises(ParameterError, match="operating_point"):
        run.operating_point


@pytest.mark.parametrize("source", ["simulated", "measured"])
def test_save_load_round_trip_keeps_source_signals_and_meta(tmp_path, source):
    run = Run(measured().t, measured().signals, {"fs_hz": 10_000.0, "note": "α"}, source=source)
    back = Run.load(run.save(tmp_path / "r.npz"))
    assert back.source == source
    assert back.meta == run.meta
    assert back.names == run.names
    for name in run.names:
        np.testing.assert_array_equal(back[name], run[name])
    np.testing.assert_array_equal(back.t, run.t)


def test_files_written_before_source_existed_load_as_simulated(tmp_path):
    path = tmp_path / "old.npz"
    atomic_savez(path, t=np.arange(4) * 1e-3, meta="{}", dte=np.zeros(4))
    assert Run.load(path).source == "simulated"


def test_positional_construction_still_works():
    run = Run(np.arange(3.0), {"dte": np.zeros(3)}, {})
    assert run.source == "simulated"


@pytest.mark.parametrize("kwargs, match", [
    ({"source": "synthetic"}, "source must be one of"),
    ({"signals": {"meta": np.zeros(5)}}, "reserved"),
    ({"signals": {"dte": np.zeros(4)}}, "shape"),
])
def test_invalid_runs_are_rejected(kwargs, match):
    args = {"t": np.arange(5.0), "signals": {"dte": np.zeros(5)}, **kwargs}
    with pytest.raises(ParameterError, match=match):
        Run(**args)


def test_with_signals_and_with_meta_return_new_runs():
    run = measured()
    louder = run.with_signals(accel_1b1_x=2 * run["accel_1b1_x"], accel_1b1_y=run["tacho"])
    tagged = run.with_meta(sensor="other", speed_rpm=600.0)
    assert louder is not run and tagged is not run
    assert run.names == ["accel_1b1_x", "tacho"]
    assert run.meta["sensor"] == "ICP 100 mV/g"
    assert louder.names == ["accel_1b1_x", "accel_1b1_y", "tacho"]
    np.testing.assert_allclose(louder["accel_1b1_x"], 2 * run["accel_1b1_x"])
    assert tagged.meta == {"fs_hz": 10_000.0, "sensor": "other", "speed_rpm": 600.0}
    assert louder.source == tagged.source == "measured"
    with pytest.raises(ParameterError, match="shape"):
        run.with_signals(tacho=np.zeros(3))


def test_summary_of_a_sine_reads_its_mean_and_rms():
    """DTE = m + A sin(ωt) over whole periods: mean m, RMS about the mean A/√2."""
    fs, n = 20_000.0, 2000                      # 50 periods of 500 Hz
    t = np.arange(n) / fs
    m, a = 2.0, 0.5
    dte_um = m + a * np.sin(2 * math.pi * 500.0 * t)
    force = -40.0 + 3.0 * np.cos(2 * math.pi * 500.0 * t)
    run = Run(t, {"dte_um": dte_um, "dte": dte_um * 1e-6 / 0.03, "F_1b1_loa": force},
              {"fs_hz": fs, "seed": 7})
    s = run.summary()
    assert math.isclose(s["dte_mean_um"], m, rel_tol=1e-12)
    assert math.isclose(s["dte_rms_um"], a / math.sqrt(2), rel_tol=1e-9)
    assert math.isclose(s["F_1b1_loa_mean_n"], -40.0, rel_tol=1e-12)
    assert math.isclose(s["F_1b1_loa_rms_n"], 3.0 / math.sqrt(2), rel_tol=1e-9)
    assert math.isclose(s["duration_s"], 0.1, rel_tol=1e-12)
    assert s["seed"] == 7 and s["n_samples"] == n and s["wall_s"] is None
    assert s["source"] == "simulated"


def test_summary_of_a_measured_record():
    s = measured().summary()
    assert s["dte_mean_um"] is None
    assert math.isclose(s["accel_1b1_x_rms_m_s2"], 1 / math.sqrt(2), rel_tol=1e-9)
    assert s["source"] == "measured"


def test_summary_of_a_simulation_has_the_cli_fields(paper_run):
    s = paper_run.summary()
    for b in Rig.paper_2016().bearing_names:
        assert math.isfinite(s[f"F_{b}_loa_mean_n"]) and s[f"F_{b}_loa_rms_n"] >= 0.0
    assert s["dte_mean_um"] > 0.0                    # the loaded mesh lags (paper Fig. 9)
    assert s["seed"] == 3 and s["realtime_factor"] > 0.0
