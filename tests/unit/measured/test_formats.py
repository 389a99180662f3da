"""Recordings in the formats labs produce (issue 28): MATLAB, UFF 58, TDMS, WAV, CSV, NPZ.

Tier: behaviour. Each reader round-trips a recording written in its format — by the format's
own library where one exists (pyuff ``UFF.write_sets``, ``nptdms.TdmsWriter``,
``scipy.io.savemat`` in the CWRU layout from a real CWRU record) and by cmsim's writer
beside it — with the same samples, rate and unit; ``cmsim compare`` and ``spectrum`` run on
a ``.mat`` and a ``.uff`` with options only (no metadata.json), ``calibrate`` on the
``.mat``, kept short (2 s records, ``--budget 10``); bad inputs give one line naming what to
do; ``cmsim import`` writes metadata that reads back. Nothing is written into the project
(tmp_path only).
"""

import json
import sys
import wave

import numpy as np
import pytest
from scipy.io import savemat

from cmsim.cli import main
from cmsim.errors import ParameterError
from cmsim.measured import data_root, load_measured, read_record
from cmsim.measured.importing import folder_metadata
from cmsim.measured.readers import WRITERS, read_file, write_signals

pyuff = pytest.importorskip("pyuff")
nptdms = pytest.importorskip("nptdms")

DATA = data_root()
CWRU = DATA / "cwru_bearing_12k_de"
needs_cwru = pytest.mark.skipif(not (CWRU / "normal_0.npz").is_file(),
                                reason="shared data absent")

#: Samples of the short records the CLI runs on (2 s at 12 kHz).
N_SHORT = 24000


def _signals(n=6000, seed=0):
    rng = np.random.default_rng(seed)
    return {"DE": rng.standard_normal(n), "FE": 0.5 * rng.standard_normal(n)}


def _uff_set(name, x, fs, unit):
    """A type-58 set as Testlab/m+p write one: time history, evenly spaced, unit label."""
    return {"type": 58, "binary": 1, "id1": name, "func_type": 1, "rsp_node": 1,
            "rsp_dir": 3, "ref_node": 0, "ref_dir": 0, "abscissa_spacing": 1,
            "abscissa_spec_data_type": 17, "abscissa_axis_lab": "Time",
            "abscissa_axis_units_lab": "s", "ordinate_spec_data_type": 12,
            "ordinate_axis_lab": name, "ordinate_axis_units_lab": unit,
            "orddenom_spec_data_type": 0, "data": np.asarray(x, dtype=float),
            "x": np.arange(len(x)) / fs}


def _cwru_mat(tmp_path, n=None):
    """A real CWRU record (normal_0, read by the existing reader) written as the CWRU
    ``.mat`` layout: ``X097_DE_time``, ``X097_FE_time`` (column vectors), ``X097RPM``."""
    rec = read_record(CWRU / "normal_0.npz")
    de, fe = rec.signals["DE"][:n], rec.signals["FE"][:n]
    path = tmp_path / "normal_0.mat"
    savemat(path, {"X097_DE_time": de[:, None], "X097_FE_time": fe[:, None],
                   "X097RPM": np.array([[1796.0]])})
    rig = tmp_path / "cwru.toml"
    rec.rig.save(rig)
    return path, rig, de, fe


# ---------------------------------------------------------------------- round trips
@pytest.mark.parametrize("suffix", sorted(WRITERS))
def test_every_writer_reads_back_the_same(tmp_path, suffix):
    """cmsim's writer and the reader beside it agree on samples, rate and units."""
    sig = _signals()
    for fs in (12000.0, 25600.0, 51200.0):
        path = write_signals(tmp_path / f"rec{suffix}", sig, fs, {"DE": "g", "FE": "m/s^2"})
        f = read_file(path)
        assert f.rate_hz == pytest.approx(fs, rel=1e-12), suffix
        assert f.units == {"DE": "g", "FE": "m/s^2"}
        assert sorted(f.signals) == ["DE", "FE"]
        tol = 2e-7 if suffix == ".wav" else 1e-12          # float32 at full scale
        for k, x in sig.items():
            peak = max(np.abs(v).max() for v in sig.values())
            assert np.allclose(f.signals[k], x, rtol=0, atol=tol * peak), (suffix, k)


@pytest.mark.parametrize("suffix", [".npz", ".mat", ".tdms"])
def test_float32_samples_are_stored_as_float32(tmp_path, suffix):
    """Where the format keeps the sample type, float32 in (a dataset's records, cmsim export)
    is float32 in the file, half the size of float64, and reads back exactly."""
    sig = {k: x.astype(np.float32) for k, x in _signals(n=600).items()}
    path = write_signals(tmp_path / f"rec{suffix}", sig, 12000.0, "g")
    if suffix == ".npz":
        stored = np.load(path)["DE"]
    elif suffix == ".mat":
        from scipy.io import loadmat
        stored = loadmat(path)["DE"]
    else:
        stored = nptdms.TdmsFile.read(str(path))["signals"]["DE"][:]
    assert stored.dtype == np.float32
    for k, x in sig.items():
        np.testing.assert_array_equal(read_file(path).signals[k], x)


def test_uff_written_by_pyuff_reads_with_names_rate_and_unit(tmp_path):
    sig, fs = _signals(), 51200.0
    path = tmp_path / "testlab.uff"
    pyuff.UFF(str(path)).write_sets([_uff_set(k, x, fs, "g") for k, x in sig.items()],
                                    mode="add")
    f = read_file(path)
    # the abscissa increment is printed with 6 digits (1.95313e-05 s): read as 51200 Hz
    assert f.rate_hz == 51200.0 and f.units == {"DE": "g", "FE": "g"}
    for k, x in sig.items():
        assert np.allclose(f.signals[k], x, rtol=0, atol=1e-12)


def test_tdms_written_by_nptdms_reads_with_names_rate_and_unit(tmp_path):
    sig, fs = _signals(), 25600.0
    path = tmp_path / "daq.tdms"
    with nptdms.TdmsWriter(str(path)) as w:
        w.write_segment([nptdms.GroupObject("Vibration")] + [
            nptdms.ChannelObject("Vibration", k, x, properties={
                "wf_increment": 1.0 / fs, "wf_start_offset": 0.0,
                "unit_string": "m/s^2"}) for k, x in sig.items()])
    f = read_file(path)
    assert f.rate_hz == fs and f.units == {"DE": "m/s^2", "FE": "m/s^2"}
    for k, x in sig.items():
        assert np.array_equal(f.signals[k], x)
    rec = read_record(path, channel="DE", speed_rpm=1800.0,
                      rig=_bearing_rig()).run.meta
    assert rec["fs_hz"] == fs and rec["sensor"]["unit"] == "m/s^2"


def _bearing_rig():
    from cmsim.discrepancy.synthetic import cwru_like_rig
    return cwru_like_rig()


@needs_cwru
def test_cwru_mat_reads_back_as_the_measured_record(tmp_path):
    """The CWRU layout: channels by variable name, XnnnRPM as the speed; options give the
    rate and the rig (no metadata.json)."""
    path, rig_file, de, fe = _cwru_mat(tmp_path)
    f = read_file(path)
    assert sorted(f.signals) == ["X097_DE_time", "X097_FE_time"]
    assert f.speed_rpm == 1796.0 and f.rate_hz is None
    from cmsim.rig import Rig
    rec = read_record(path, channel="X097_DE_time", fs_hz=12000.0, rig=Rig.load(rig_file))
    assert rec.fs_hz == 12000.0 and rec.channel == "X097_DE_time"
    assert np.array_equal(rec.signals["X097_DE_time"], de)
    assert np.array_equal(rec.signals["X097_FE_time"], fe)
    assert rec.op.speed_rpm == pytest.approx(1796.0, rel=5e-3)
    assert "sample rate and speed agree" in " ".join(rec.meta["notes"])


def test_wav_counts_with_a_calibration_factor(tmp_path):
    """A 16-bit WAV in counts: the factor from metadata.json or the caller gives physical
    units; the header rate is checked against a stated one as before."""
    x = np.round(np.random.default_rng(4).standard_normal(8000) * 3000).astype("<i2")
    path = tmp_path / "rec.wav"
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(8000)
        w.writeframes(x.tobytes())
    rec = read_record(path, calibration=1e-3, unit="g", speed_rpm=1800.0,
                      rig=_bearing_rig())
    assert np.allclose(rec.signals["ch0"], 1e-3 * x)
    assert rec.unit_scale == pytest.approx(9.80665)
    (tmp_path / "metadata.json").write_text(json.dumps({"recordings": [
        {"file": "rec.wav", "calibration": 2e-3, "fs_hz": 8000, "channels": ["DE"]}]}))
    rec = read_record(path, speed_rpm=1800.0, rig=_bearing_rig())
    assert np.allclose(rec.signals["DE"], 2e-3 * x) and rec.fs_hz == 8000
    with pytest.raises(ParameterError, match=r'"calibration" says .*0\.002.* 0\.001'):
        read_record(path, calibration=1e-3, speed_rpm=1800.0, rig=_bearing_rig())


# ---------------------------------------------------------------------- the CLI, options only
@needs_cwru
@pytest.mark.parametrize("kind", [".mat", ".uff"])
def test_compare_and_spectrum_on_options_only(tmp_path, capsys, kind):
    path, rig, de, _ = _cwru_mat(tmp_path, N_SHORT)
    opts = ["--fs-hz", "12000", "--speed-rpm", "1797", "--rig", str(rig)]
    if kind == ".uff":
        path = write_signals(tmp_path / "normal_0.uff", {"DE": de}, 12000.0, "g")
        opts = opts[2:]                                  # the file states the rate
    channel = ["--channel", "X097_DE_time"] if kind == ".mat" else []
    assert main(["compare", str(path), *channel, *opts, "--budget", "10", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["finding"] and out["simulations"] <= 10
    assert main(["spectrum", str(path), *opts, "--top", "3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["unit"] == ("g" if kind == ".uff" else "") and out["n_peaks"] <= 3
    assert not (tmp_path / "metadata.json").exists()


@needs_cwru
def test_calibrate_on_options_only(tmp_path, capsys, monkeypatch):
    """A machine from a CWRU ``.mat`` that states neither rate nor unit: the options give
    them. (Calibrate reads a record as compare does, by ``read_record``: the UFF case above
    covers the reader; a second calibration would only build the same library again.)"""
    path, rig, _, _ = _cwru_mat(tmp_path, N_SHORT)
    machine = tmp_path / "m.toml"
    assert main(["calibrate", str(path), "--channel", "X097_DE_time", "--fs-hz", "12000",
                 "--speed-rpm", "1797", "--rig", str(rig), "--out", str(machine),
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["fs_hz"] == 12000.0 and out["channel"] == "X097_DE_time"
    assert machine.is_file() and not (tmp_path / "metadata.json").exists()
    # against it, the model runs only to refine a named cause: with the kernels cached the
    # command does not load them up front (0.4 s of a 2-s comparison with no finding)
    from cmsim.cli import app
    from cmsim.dynamics import simulation

    asked = []
    monkeypatch.setattr(simulation, "kernels_cached", lambda: True)
    monkeypatch.setattr(app, "_notice_compile", lambda args, integrates=True: asked.append(
        integrates))
    assert main(["compare", str(path), "--machine", str(machine), "--fs-hz", "12000",
                 "--speed-rpm", "1797", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["mode"] == "machine" and asked == [False]


# ---------------------------------------------------------------------- bad inputs
def _error(capsys, argv):
    """(status, the JSON error object, stderr lines) of a command run with --json."""
    status = main(argv + ["--json"])
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err
    return status, json.loads(cap.out), cap.err.strip().splitlines()


@needs_cwru
def test_missing_channel_lists_the_channels_of_the_file(tmp_path, capsys):
    path, rig, _, _ = _cwru_mat(tmp_path, N_SHORT)
    status, err, lines = _error(capsys, ["compare", str(path), "--channel", "X097_BA_time",
                                         "--fs-hz", "12000", "--rig", str(rig)])
    assert status == 2 and len(lines) == 1 and err["option"] == "--channel"
    assert "X097_DE_time" in err["error"] and "X097_FE_time" in err["error"]


def test_a_rate_the_file_states_against_another_fs_hz(tmp_path, capsys):
    path = write_signals(tmp_path / "rec.uff", _signals(), 25600.0, "g")
    status, err, lines = _error(capsys, ["spectrum", str(path), "--fs-hz", "12000"])
    assert status == 2 and len(lines) == 1 and err["option"] == "--fs-hz"
    assert "25600 Hz" in err["error"] and "12000 Hz" in err["error"]
    with pytest.raises(ParameterError, match="25600 Hz.*fs_hz says .*12000 Hz"):
        read_record(path, fs_hz=12000.0, rig=_bearing_rig())


def test_matlab_v73_is_refused_with_what_to_do(tmp_path, monkeypatch):
    """A v7.3 file (HDF5 inside; its header says version 0x0200): without h5py, one line
    naming the file and both ways out."""
    path = tmp_path / "big.mat"
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan 1 2024 HDF5 schema"
    path.write_bytes(header.ljust(116, b" ") + b"\0" * 8 + b"\x00\x02" + b"IM" + b"\0" * 512)
    monkeypatch.setitem(sys.modules, "h5py", None)
    with pytest.raises(ParameterError) as exc:
        read_file(path)
    msg = str(exc.value)
    assert str(path) in msg and "v7.3" in msg and "-v7" in msg and "h5py" in msg


def test_matlab_v73_reads_through_h5py_when_present(tmp_path, monkeypatch):
    """With h5py installed, a v7.3 file's numeric variables are its channels (MATLAB stores
    them column-major: a (1, n) HDF5 dataset is the (n, 1) variable); a stand-in h5py here,
    the real one being optional."""
    import types

    class Dataset(np.ndarray):
        pass

    x = np.arange(10.0)
    data = {"X097_DE_time": x[None, :].view(Dataset), "X097RPM": np.array([[1797.0]]).view(
        Dataset), "label": "not numeric"}

    class File(dict):
        def __init__(self, path, mode):
            super().__init__(data)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

    monkeypatch.setitem(sys.modules, "h5py", types.SimpleNamespace(File=File,
                                                                    Dataset=Dataset))
    path = tmp_path / "big.mat"
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan 1 2024 HDF5 schema"
    path.write_bytes(header.ljust(116, b" ") + b"\0" * 8 + b"\x00\x02" + b"IM" + b"\0" * 512)
    f = read_file(path)
    assert list(f.signals) == ["X097_DE_time"] and np.array_equal(f.signals["X097_DE_time"], x)
    assert f.speed_rpm == 1797.0


def test_uff_without_a_type_58_set_is_refused(tmp_path):
    path = tmp_path / "geometry.uff"
    pyuff.UFF(str(path)).write_sets([{"type": 15, "node_nums": [1, 2], "def_cs": [0, 0],
                                      "disp_cs": [0, 0], "color": [1, 1], "x": [0.0, 1.0],
                                      "y": [0.0, 0.0], "z": [0.0, 0.0]}], mode="add")
    with pytest.raises(ParameterError, match="no type-58 data set.*type \\[15\\]"):
        read_file(path)


@pytest.mark.parametrize("suffix, module, extra", [(".uff", "pyuff", "uff"),
                                                   (".tdms", "nptdms", "tdms")])
def test_missing_optional_library_names_the_extra(tmp_path, capsys, monkeypatch, suffix,
                                                  module, extra):
    path = write_signals(tmp_path / f"rec{suffix}", _signals(), 12000.0)
    monkeypatch.setitem(sys.modules, module, None)
    status, err, lines = _error(capsys, ["spectrum", str(path)])
    assert status == 2 and len(lines) == 1
    assert f"pip install cmsim[{extra}]" in err["error"] and module in err["error"]
    with pytest.raises(ParameterError, match=rf"cmsim\[{extra}\]"):
        write_signals(tmp_path / f"other{suffix}", _signals(), 12000.0)


def test_no_metadata_and_no_rate_says_what_to_give(tmp_path, capsys):
    path = tmp_path / "rec.npz"
    np.savez(path, DE=np.random.default_rng(0).standard_normal(8000))
    status, err, _ = _error(capsys, ["compare", str(path)])
    assert status == 2 and err["option"] == "RECORD"
    assert "metadata.json" in err["error"] and "--fs-hz" in err["error"] \
        and "cmsim import" in err["error"]


# ---------------------------------------------------------------------- cmsim import
def test_import_writes_metadata_that_reads_back(tmp_path, capsys):
    folder = tmp_path / "lab"
    folder.mkdir()
    sig = _signals(8000)
    write_signals(folder / "a.uff", sig, 12000.0, "g")
    pyuff_free = folder / "b.npz"
    np.savez(pyuff_free, DE=sig["DE"], FE=sig["FE"])        # states neither rate nor unit
    argv = ["import", str(folder), "--fs-hz", "12000", "--speed-rpm", "1797", "--unit", "g"]
    assert main(argv + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["n_recordings"] == 2 and out["fs_hz"] == 12000.0
    assert out["units"] == {"DE": "g", "FE": "g"}
    meta = json.loads((folder / "metadata.json").read_text())
    assert [r["file"] for r in meta["recordings"]] == ["a.uff", "b.npz"]
    assert all(r["shaft_speed_rpm"] == 1797.0 for r in meta["recordings"])
    for name in ("a.uff", "b.npz"):
        rec = read_record(folder / name, channel="DE", rig=_bearing_rig())
        assert rec.fs_hz == 12000.0 and rec.unit_scale == pytest.approx(9.80665)
        assert np.allclose(rec.signals["DE"], sig["DE"])
    # an existing file is kept unless --force; a disagreeing option writes nothing
    before = (folder / "metadata.json").read_text()
    status, err, _ = _error(capsys, argv)
    assert status == 2 and err["option"] == "--out" and "--force" in err["error"]
    status, err, _ = _error(capsys, ["import", str(folder), "--force", "--unit", "V"])
    assert status == 2 and err["option"] == "--unit" and "'g'" in err["error"]
    assert (folder / "metadata.json").read_text() == before
    # with the geometry added by hand, the folder is a dataset (what cmsim evaluate reads)
    meta = json.loads(before)
    meta["geometry"]["bearings"] = {"de": {"n_balls": 9, "ball_diameter_mm": 7.94,
                                           "pitch_diameter_mm": 39.04}}
    (folder / "metadata.json").write_text(json.dumps(meta))
    ds = load_measured(folder)
    assert len(ds) == 2 and not ds.unreadable
    assert list(ds.manifest["fs_hz"]) == [12000.0, 12000.0]
    assert main(["import", str(folder), "--force"]) == 0   # the files, then metadata.json
    capsys.readouterr()
    again = json.loads((folder / "metadata.json").read_text())
    assert again["recordings"][1]["fs_hz"] == 12000.0
    assert again["geometry"] == meta["geometry"]


def test_import_names_a_wavs_channels(tmp_path):
    folder = tmp_path / "wav"
    folder.mkdir()
    x = (np.random.default_rng(5).standard_normal((8000, 2)) * 1000).astype("<i2")
    with wave.open(str(folder / "r.wav"), "wb") as w:
        w.setnchannels(2)
        w.setsampwidth(2)
        w.setframerate(12000)
        w.writeframes(x.tobytes())
    meta, undocumented, _, _ = folder_metadata(folder, channels=["DE", "FE"],
                                               calibration=1e-3)
    rec = meta["recordings"][0]
    assert rec["channels"] == ["DE", "FE"] and rec["fs_hz"] == 12000.0
    assert rec["calibration"] == 1e-3
    assert "r.wav: shaft speed" in undocumented and "unit of DE" in undocumented
    with pytest.raises(ParameterError, match=r"holds 2 unnamed signal\(s\) \(ch0, ch1\) "
                                             r"but channel gives 1 names \(DE\); give one "
                                             r"name per signal, in the file's order"):
        folder_metadata(folder, channels=["DE"])


def test_import_leaves_out_files_cmsim_wrote(tmp_path, capsys):
    """A run or dataset record (an .npz with a meta array) states its own rate, speed and
    rig: import leaves it out, names it on stderr, and refuses a folder of nothing else."""
    folder = tmp_path / "mixed"
    folder.mkdir()
    np.savez(folder / "a.npz", DE=_signals(4000)["DE"])
    np.savez(folder / "sim.npz", t=np.arange(4000) / 12000.0, accel_1b1_y=np.zeros(4000),
             meta=np.array("{}"))
    assert main(["import", str(folder), "--fs-hz", "12000", "--json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert [r["file"] for r in out["recordings"]] == ["a.npz"]
    assert out["channels"] == ["DE"] and out["skipped"] == ["sim.npz"]
    assert any("sim.npz" in w and "need no metadata" in w for w in out["warnings"])
    (folder / "a.npz").unlink()
    (folder / "metadata.json").unlink()
    status, err, _ = _error(capsys, ["import", str(folder), "--fs-hz", "12000"])
    assert status == 2 and err["option"] == "DIR"
    assert "sim.npz" in err["error"] and "cmsim wrote" in err["error"]


def test_import_reads_the_folders_metadata_and_keeps_hand_written_keys(tmp_path, capsys):
    """metadata.json beside the files is a source (file > metadata.json > options), and
    --force keeps every key import does not write (geometry, sensor position, condition)."""
    folder = tmp_path / "lab"
    folder.mkdir()
    np.savez(folder / "b.npz", DE=_signals(4000)["DE"])      # states neither rate nor unit
    geometry = {"gears": None, "bearings": {"de": {"n_balls": 9, "ball_diameter_mm": 7.94,
                                                   "pitch_diameter_mm": 39.04}}}
    (folder / "metadata.json").write_text(json.dumps({
        "dataset": "lab", "fs_hz": 12000, "geometry": geometry, "rig": "a test stand",
        "sensors": {"DE": {"near": "de", "direction": "radial", "unit": "g"}},
        "recordings": [{"file": "b.npz", "shaft_speed_rpm": 1797, "condition": "healthy"}]}))
    other = tmp_path / "x.json"
    assert main(["import", str(folder), "--out", str(other), "--json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert out["undocumented"] == [] and "warnings" not in out
    rec = out["recordings"][0]
    assert rec["fs_hz"] == 12000.0 and rec["shaft_speed_rpm"] == 1797.0
    assert out["units"] == {"DE": "g"}
    assert main(["import", str(folder), "--force"]) == 0
    capsys.readouterr()
    meta = json.loads((folder / "metadata.json").read_text())
    assert meta["geometry"] == geometry and meta["rig"] == "a test stand"
    assert meta["sensors"]["DE"] == {"near": "de", "direction": "radial", "unit": "g"}
    assert meta["recordings"][0]["condition"] == "healthy"
    assert meta["recordings"][0]["n_samples"] == 4000
    status, err, _ = _error(capsys, ["import", str(folder), "--force", "--fs-hz", "24000"])
    assert status == 2 and err["option"] == "--fs-hz"
    assert 'metadata.json "fs_hz"' in err["error"]


def test_import_warnings_name_the_option(tmp_path, capsys):
    folder = tmp_path / "bare"
    folder.mkdir()
    np.savez(folder / "b.npz", DE=_signals(4000)["DE"])
    assert main(["import", str(folder)]) == 0
    err = capsys.readouterr().err
    assert "give --fs-hz" in err and "give --speed-rpm" in err and "give --unit" in err


# ---------------------------------------------------------------------- CSV forms
@pytest.mark.parametrize("time_name, scale", [("t", 1.0), ("Time", 1.0), ("TIME_S", 1.0),
                                              ("Time (s)", 1.0), ("time [s]", 1.0),
                                              ("time [ms]", 1e3), ("t_ms", 1e3)])
@pytest.mark.parametrize("sep", [",", ";", "\t"])
def test_csv_time_column_forms_units_and_separators(tmp_path, time_name, scale, sep):
    """The time column in the forms DAQ exports write it, units in [] or (), and the
    separator sniffed (a ';' file with decimal commas, as a European locale writes it)."""
    x = _signals(50)["DE"]
    t = np.arange(50) / 12000.0 * scale
    comma = sep == ";"
    fmt = (lambda v: f"{v:.9g}".replace(".", ",")) if comma else (lambda v: f"{v:.9g}")
    lines = [sep.join([time_name, "acc (g)", "ref [m/s^2]"])]
    lines += [sep.join([fmt(a), fmt(b), fmt(2 * b)]) for a, b in zip(t, x)]
    path = tmp_path / "r.csv"
    path.write_text("\n".join(lines) + "\n")
    f = read_file(path)
    assert f.rate_hz == pytest.approx(12000.0, rel=1e-6)
    assert sorted(f.signals) == ["acc", "ref"]
    assert f.units == {"acc": "g", "ref": "m/s^2"}
    assert np.allclose(f.signals["acc"], x, rtol=1e-8)


@pytest.mark.parametrize("gap", ["a 10 ms gap", "a missing sample", "a step back"])
def test_csv_uneven_time_steps_are_refused(tmp_path, gap):
    t = np.arange(2000) / 12000.0
    if gap == "a 10 ms gap":
        t[1000:] += 0.01
    elif gap == "a missing sample":
        t = np.delete(np.arange(2001) / 12000.0, 700)
    else:
        t[500] = t[498]
    path = tmp_path / "u.csv"
    path.write_text("time_s,x [g]\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in
                                                zip(t, _signals(2000)["DE"])))
    with pytest.raises(ParameterError, match="not evenly spaced"):
        read_file(path)


def test_csv_too_short_for_a_time_base_says_so(tmp_path):
    """Three evenly spaced rows were refused as "not evenly spaced (step 0 ...)": too few
    stamps to read a rate from is what is wrong."""
    path = tmp_path / "s.csv"
    path.write_text("time,acc\n0,0.1\n0.001,0.2\n0.002,0.3\n")
    with pytest.raises(ParameterError, match="holds 3 stamps, too few to read a sample rate"):
        read_file(path)


# ---------------------------------------------------------------------- .mat forms
def test_mat_time_vector_is_the_time_base(tmp_path):
    x = _signals(3000)["DE"]
    savemat(tmp_path / "r.mat", {"t": np.arange(3000) / 25600.0, "acc": x})
    f = read_file(tmp_path / "r.mat")
    assert list(f.signals) == ["acc"] and f.rate_hz == pytest.approx(25600.0)
    t = np.arange(3000) / 25600.0
    t[2000:] += 0.01
    savemat(tmp_path / "gap.mat", {"time": t, "acc": x})
    with pytest.raises(ParameterError, match="not evenly spaced"):
        read_file(tmp_path / "gap.mat")
    savemat(tmp_path / "both.mat", {"t": np.arange(3000) / 25600.0, "acc": x, "fs": 12000.0})
    with pytest.raises(ParameterError, match="different sample rates"):
        read_file(tmp_path / "both.mat")


@pytest.mark.parametrize("transpose", [False, True])
def test_mat_matrix_is_split_into_channels(tmp_path, transpose):
    """The usual DAQ export: one n x k matrix ``data``, columns the channels (n > k)."""
    data = np.column_stack([_signals(3000, seed=s)["DE"] for s in range(3)])
    savemat(tmp_path / "d.mat", {"data": data.T if transpose else data, "Fs": 12000.0})
    f = read_file(tmp_path / "d.mat")
    assert list(f.signals) == ["data_0", "data_1", "data_2"] and f.rate_hz == 12000.0
    assert np.allclose(f.signals["data_2"], data[:, 2])


def test_mat_rpm_scalars_of_different_values_are_ambiguous(tmp_path):
    x = _signals(3000)["DE"]
    savemat(tmp_path / "same.mat", {"acc": x, "X097RPM": 1796.0, "motor_rpm": 1796.0})
    assert read_file(tmp_path / "same.mat").speed_rpm == 1796.0
    savemat(tmp_path / "two.mat", {"acc": x, "X097RPM": 1796.0, "motor_rpm": 1750.0})
    with pytest.raises(ParameterError, match="ambiguous") as exc:
        read_file(tmp_path / "two.mat")
    assert "X097RPM = 1796" in str(exc.value) and "motor_rpm = 1750" in str(exc.value)


# ---------------------------------------------------------------------- --unit
def test_unit_means_every_unstated_channel_in_read_record_as_in_import(tmp_path):
    """One rule for --unit: every channel whose file and metadata state none (as
    --calibration), in compare/spectrum (read_record) as in import."""
    folder = tmp_path / "u"
    folder.mkdir()
    sig = _signals(8000)
    np.savez(folder / "r.npz", DE=sig["DE"], FE=sig["FE"])
    rec = read_record(folder / "r.npz", channel="DE", rig=_bearing_rig(), fs_hz=12000.0,
                      unit="g")
    meta, _, _, _ = folder_metadata(folder, fs_hz=12000.0, unit="g")
    assert rec.run.meta["units"] == {"DE": "g", "FE": "g"}
    assert {c: s["unit"] for c, s in meta["sensors"].items()} == rec.run.meta["units"]


@pytest.mark.parametrize("unit", ["", "furlongs", "  "])
@pytest.mark.parametrize("command", ["import", "spectrum"])
def test_unknown_units_are_refused_listing_the_known(tmp_path, capsys, unit, command):
    np.savez(tmp_path / "r.npz", DE=_signals(4000)["DE"])
    target = tmp_path if command == "import" else tmp_path / "r.npz"
    status, err, lines = _error(capsys, [command, str(target), "--fs-hz", "12000",
                                         "--unit", unit])
    assert status == 2 and err["option"] == "--unit" and len(lines) == 1
    assert "m/s^2" in err["error"] and "V" in err["error"]
    assert not (tmp_path / "metadata.json").exists()
    with pytest.raises(ParameterError, match="allowed: g"):
        folder_metadata(tmp_path, fs_hz=12000.0, unit=unit)


def test_unit_names_of_the_help_are_the_unit_table():
    from cmsim.cli.options import UNIT_NAMES
    from cmsim.measured.schema import known_units
    assert UNIT_NAMES == known_units()


# ---------------------------------------------------------------------- inferred speed
@needs_cwru
def test_spectrum_says_the_speed_was_inferred_and_from_what(tmp_path, capsys):
    """CWRU normal_0 as a WAV states no speed: the spectrum's speed comes from the signal,
    and the text, the JSON and a stderr warning say so (as compare prints it)."""
    _, rig, de, _ = _cwru_mat(tmp_path, N_SHORT)
    write_signals(tmp_path / "n.wav", {"DE": de}, 12000.0, "g")
    argv = ["spectrum", str(tmp_path / "n.wav"), "--rig", str(rig), "--top", "3"]
    assert main(argv + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    how = out["inferred"]["speed_rpm"]["how"]
    assert how and any("inferred from the signal" in w and "--speed-rpm" in w
                       for w in out["warnings"])
    assert main(argv) == 0
    cap = capsys.readouterr()
    assert "shaft speed inferred from the signal" in cap.out and how in cap.out
    assert "warning: shaft speed" in cap.err
    assert main(argv + ["--speed-rpm", "1796", "--json"]) == 0     # stated: nothing inferred
    out = json.loads(capsys.readouterr().out)
    assert out["inferred"] == {} and "warnings" not in out


@pytest.mark.parametrize("command", ["compare"])
def test_no_metadata_and_no_rig_says_how_to_get_a_rig(tmp_path, capsys, command):
    np.savez(tmp_path / "rec.npz", DE=_signals(8000)["DE"])
    status, err, lines = _error(capsys, [command, str(tmp_path / "rec.npz"), "--fs-hz",
                                         "12000"])
    assert status == 2 and err["option"] == "--rig" and len(lines) == 1
    assert "the recording has no geometry: give --rig FILE.toml" in err["error"]
    assert "neither bearing geometry" not in err["error"]


def test_a_spectrum_without_geometry_names_the_shaft_only(tmp_path, capsys):
    """Issue 48: a recording with neither metadata.json nor --rig was refused by spectrum
    ("give --rig"); a spectrum needs no model: it is shown, its peaks named by the shaft
    rate alone, and says so."""
    t = np.arange(24000) / 12000.0
    x = np.sin(2 * np.pi * 30.0 * t) + 0.5 * np.sin(2 * np.pi * 60.0 * t)
    np.savez(tmp_path / "rec.npz",
             DE=x + 0.01 * np.random.default_rng(0).standard_normal(t.size))
    argv = ["spectrum", str(tmp_path / "rec.npz"), "--fs-hz", "12000", "--speed-rpm", "1800"]
    assert main(argv + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["bearing"] is None and out["families"] == {"fr": 30.0}
    assert {p["label"] for p in out["peaks"][:2]} == {"1fr", "2fr"}, out["peaks"][:3]
    assert main(argv) == 0
    assert "no geometry, peaks named by the shaft rate only" in capsys.readouterr().out
