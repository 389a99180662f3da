"""Data out (issue 28): signal files, the windowed Parquet layout, the ML channel rule.

Test tier: behaviour contracts (no physics). Every export format but parquet is written by
the measured writer beside its reader and reads back through that reader with the same
samples, rate and units (uff also through pyuff itself); the windowed Parquet holds the
windows of ``to_arrays`` (pandas, pyarrow and the HuggingFace loader when installed) and no
group in two splits; ML loaders leave the simulated-only channels out unless asked; an
interrupted export leaves nothing and a repeated one is refused without ``force``. The
dataset has 4 records of 0.02 s.
"""

import dataclasses
import json
import sys

import numpy as np
import pandas as pd
import pytest

from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.datasets import export as export_mod
from cmsim.datasets.export import FORMATS, export
from cmsim.datasets.windows import split_of
from cmsim.errors import ParameterError
from cmsim.frequencies import rig_frequencies
from cmsim.measured.model_rig import documented_frequencies, model_rig
from cmsim.measured.readers import WRITERS, read_file, read_signals
from cmsim.measured.schema import answer_key, rig_geometry
from cmsim.run import Run

SPEC = {
    "dataset": {"name": "tiny", "records": 4, "seed": 3},
    "rig": {"builtin": "paper_2016"},
    "faults": {"healthy_share": 0.5,
               "types": [{"type": "outer_race", "bearing": ["1b1"],
                          "size_m": {"min": 0.5e-3, "max": 1.5e-3}, "depth_m": 1e-4}]},
    "sensor": {"channels": ["accel_1b1_y", "tacho", "dte_um"], "fs_hz": 25600.0,
               "duration_s": 0.02, "warmup_s": 0.01},
}
MEASURABLE = ["accel_1b1_y", "tacho"]


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    out = tmp_path_factory.mktemp("export") / "ds"
    generate_dataset(DatasetSpec.from_dict(SPEC), out, workers=1, progress=False)
    return out


# ---------------------------------------------------------------------- channel rule
def test_ml_defaults_leave_simulated_only_channels_out(made):
    ds = load(made)
    assert ds.select_channels() == MEASURABLE
    X, y, g = ds.to_arrays(window=128)
    assert X.shape[1] == 2
    np.testing.assert_array_equal(X[0, 0], ds.record(0).signals["accel_1b1_y"][:128])
    Xd, _, _ = ds.to_arrays(["dte_um"], window=128)                 # asked by name
    np.testing.assert_array_equal(Xd[0, 0], ds.record(0).signals["dte_um"][:128])
    Xa, _, _ = ds.to_arrays(window=128, include_simulated=True)
    assert Xa.shape[1] == 3
    np.testing.assert_array_equal(Xa[:, :2], X)
    assert next(ds.iter_arrays(window=128))[0].shape[1] == 2
    with pytest.raises(ParameterError, match=r"'F_1b1_loa' is not in this dataset.*dte_um"):
        ds.to_arrays(["F_1b1_loa"], window=128)


def test_a_dataset_of_simulated_signals_only_needs_them_named(made, monkeypatch):
    ds = load(made)
    monkeypatch.setattr(ds, "channels", ("dte_um",))
    with pytest.raises(ParameterError, match="real machine") as err:
        ds.to_arrays(window=128)
    assert err.value.param == "channels"
    assert ds.to_arrays(window=128, include_simulated=True)[0].shape[1] == 1


# ---------------------------------------------------------------------- signal files
FILE_FORMATS = [f for f in FORMATS if f != "parquet"]


@pytest.mark.parametrize("fmt", FILE_FORMATS)
def test_run_round_trips_through_the_measured_reader(made, tmp_path, fmt):
    """The file states the rate and units itself; a WAV is float32 at full scale (its
    calibration factor restores the values to float32 precision of the peak)."""
    src = made / "records" / "000002.npz"
    run = Run.load(src)
    res = export(src, tmp_path / "out", fmt, channels=["accel_1b1_y", "dte_um"])
    assert res["kind"] == "run" and res["units"] == {"accel_1b1_y": "m/s²", "dte_um": "µm"}
    f = read_file(tmp_path / "out" / f"000002.{fmt}")
    assert f.rate_hz == pytest.approx(25600.0, rel=1e-12)
    assert f.units == {"accel_1b1_y": "m/s²", "dte_um": "µm"}
    assert sorted(f.signals) == ["accel_1b1_y", "dte_um"]
    for c in ("accel_1b1_y", "dte_um"):
        if fmt == "wav":
            atol = 2 ** -23 * np.abs(np.stack([run[k] for k in f.signals])).max()
            np.testing.assert_allclose(f.signals[c], run[c], rtol=0, atol=atol)
        else:
            np.testing.assert_array_equal(f.signals[c], run[c])
    meta = json.loads((tmp_path / "out" / "metadata.json").read_text())
    assert meta["fs_hz"] == pytest.approx(25600.0)
    assert meta["sensors"]["accel_1b1_y"]["unit"] == "m/s²"
    assert answer_key(meta["recordings"][0])["fault_label"] == "outer_race"
    # the geometry is the run's rig: the file reads back with no rig given (the model and
    # the lines a measured record gets from its metadata)
    model_rig(meta["geometry"], near=meta["sensors"]["accel_1b1_y"]["near"])
    want = rig_frequencies(run.rig, run.operating_point)
    got = documented_frequencies(meta["geometry"], run.operating_point.shaft_hz)
    assert got.gmf_hz == pytest.approx(want.gmf_hz, rel=1e-9)
    assert got.bearing("1b1").bpfo_hz == pytest.approx(want.bearing("1b1").bpfo_hz, rel=1e-9)


@pytest.mark.parametrize("faults, label", [
    ([], "healthy"),
    ([{"type": "inner_race", "bearing": "2b1", "size_m": 1e-3, "depth_m": 1e-4,
       "label": "inner_race@2b1 size=1mm depth=0.1mm"}], "inner_race")])
def test_a_plain_run_exports_its_faults_as_the_answer_key(made, tmp_path, faults, label):
    """A run of cmsim simulate keeps its faults in meta["faults"] (no dataset labels)."""
    rec = Run.load(made / "records" / "000002.npz")
    meta = {k: v for k, v in rec.meta.items() if k != "labels"}
    run = dataclasses.replace(rec, meta={**meta, "faults": faults})
    export(run, tmp_path / "out", "npz")
    entry = json.loads((tmp_path / "out" / "metadata.json").read_text())["recordings"][0]
    assert answer_key(entry)["fault_label"] == label
    assert entry["condition"] == ("healthy" if label == "healthy" else "faulty")
    if faults:
        assert entry["fault_component"] == "2b1"
        assert entry["fault_severity"] == pytest.approx(1e-3)


def test_the_geometry_of_a_bearing_rig_reads_back_as_the_same_lines():
    """The geometry block of a rig gives, through the measured reader's model, the rig's own
    defect frequencies (the contact angle included)."""
    from cmsim.rig import OperatingPoint
    from cmsim.rig.presets import PRESETS

    for make in PRESETS.values():
        rig = make()
        op = OperatingPoint(speed_rpm=1500.0)
        want = rig_frequencies(rig, op)
        got = documented_frequencies(rig_geometry(rig), op.shaft_hz)
        assert got.gmf_hz == pytest.approx(want.gmf_hz)
        for name in rig.bearing_names:
            for key in ("bpfo_hz", "bpfi_hz", "bsf_hz", "ftf_hz"):
                assert getattr(got.bearing(name), key) == pytest.approx(
                    getattr(want.bearing(name), key), rel=1e-9), (name, key)


def test_uff_round_trips_through_pyuff(made, tmp_path):
    pyuff = pytest.importorskip("pyuff")
    src = made / "records" / "000002.npz"
    run = Run.load(src)
    export(src, tmp_path / "out", "uff")
    sets = pyuff.UFF(str(tmp_path / "out" / "000002.uff")).read_sets()
    assert [s["id1"].strip() for s in sets] == MEASURABLE
    for s in sets:
        name = s["id1"].strip()
        assert s["type"] == 58 and s["abscissa_inc"] == pytest.approx(1 / 25600.0)
        assert s["ordinate_axis_units_lab"].strip() == {"accel_1b1_y": "m/s²",
                                                        "tacho": "V"}[name]
        np.testing.assert_array_equal(s["data"], run[name])


def test_uff_without_pyuff_names_the_extra(made, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyuff", None)
    with pytest.raises(ParameterError, match=r"pip install cmsim\[uff\]"):
        export(made, tmp_path / "out", "uff")
    assert not list(tmp_path.iterdir())


def test_dataset_export_one_file_per_record_and_the_labels(made, tmp_path):
    ds = load(made)
    res = export(made, tmp_path / "out", "npz", seed=1)
    assert res["files"] == len(ds) == 4 and res["channels"] == MEASURABLE
    labels = pd.read_csv(tmp_path / "out" / "labels.csv", dtype={"record_id": str, "group": str})
    assert list(labels["record_id"]) == list(ds.manifest["record_id"])
    assert list(labels["label"]) == list(ds.manifest["fault_label"])
    assert list(labels["split"]) == [split_of(g, 1) for g in labels["group"]]
    for rid in labels["record_id"]:
        signals, _ = read_signals(tmp_path / "out" / f"{rid}.npz")
        assert sorted(signals) == MEASURABLE
        np.testing.assert_array_equal(signals["tacho"], ds.record(rid).signals["tacho"])
        assert np.load(tmp_path / "out" / f"{rid}.npz")["tacho"].dtype == np.float32
    meta = json.loads((tmp_path / "out" / "metadata.json").read_text())
    assert [r["file"] for r in meta["recordings"]] == list(labels["file"])
    assert [answer_key(r)["fault_label"] for r in meta["recordings"]] == list(labels["label"])
    assert meta["geometry"] == json.loads(json.dumps(rig_geometry(ds.record(0).rig)))
    assert all(s["direction"] for s in meta["sensors"].values())


def test_export_refuses_an_existing_out_and_force_replaces_it(made, tmp_path):
    out = tmp_path / "out"
    export(made, out, "csv")
    with pytest.raises(ParameterError, match="exists") as err:
        export(made, out, "npz")
    assert err.value.param == "out"
    export(made, out, "npz", force=True)
    assert sorted(p.suffix for p in out.iterdir()) == [".csv", ".json"] + [".npz"] * 4
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]     # no staging left


@pytest.mark.parametrize("where", [".", "records", ".."])
def test_export_never_replaces_its_source(made, tmp_path, where):
    """An out that is, lies in or holds the source is refused even with force."""
    before = sorted(p.name for p in made.rglob("*"))
    with pytest.raises(ParameterError, match="source") as err:
        export(made, (made / where).resolve(), "csv", force=True)
    assert err.value.param == "out"
    assert sorted(p.name for p in made.rglob("*")) == before


def test_a_run_is_not_exported_as_parquet(made, tmp_path):
    """Parquet is a dataset's windowed layout; a run is pointed at the signal formats."""
    with pytest.raises(ParameterError, match="windowed layout.*npz") as err:
        export(made / "records" / "000002.npz", tmp_path / "out", "parquet")
    assert err.value.param == "format" and not list(tmp_path.iterdir())


def test_an_interrupted_export_leaves_nothing(made, tmp_path, monkeypatch):
    real, calls = export_mod._write_signals, []

    def interrupted(path, *args):
        calls.append(path)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(path, *args)

    monkeypatch.setattr(export_mod, "_write_signals", interrupted)
    with pytest.raises(KeyboardInterrupt):
        export(made, tmp_path / "out", "wav")
    assert len(calls) == 3 and not list(tmp_path.iterdir())


@pytest.mark.parametrize("bad, match", [
    ({"fmt": "mp3"}, "format"), ({"channels": ["nope"]}, "nope"),
    ({"fractions": (0.5, 0.5, 0.5)}, "fractions"), ({"group_by": "nope"}, "group_by"),
    ({"window": 64, "fmt": "csv"}, "window")])
def test_bad_input_is_named(made, tmp_path, bad, match):
    kwargs = {"fmt": "npz", **bad}
    with pytest.raises(ParameterError, match=match):
        export(made, tmp_path / "out", kwargs.pop("fmt"), **kwargs)
    assert not list(tmp_path.iterdir())


def test_not_a_run_nor_a_dataset(tmp_path):
    np.savez(tmp_path / "x.npz", a=np.zeros(3))
    for src in (tmp_path / "x.npz", tmp_path):
        with pytest.raises(ParameterError, match="not a cmsim run|without dataset.json"):
            export(src, tmp_path / "out", "csv")


def test_every_format_is_one_writer(tmp_path, monkeypatch):
    """Each format but parquet is the measured writer of its suffix (the one beside its
    reader), and every measured writer is a format (.unv is .uff by another name)."""
    assert set(FORMATS) == {s.lstrip(".") for s in WRITERS} - {"unv"} | {"parquet"}
    used = []
    for suffix in WRITERS:
        monkeypatch.setitem(WRITERS, suffix, lambda path, *a, s=suffix: used.append(s))
    for fmt in FILE_FORMATS:
        export_mod._write_signals(tmp_path / f"x.{fmt}", {"a": np.zeros(4)}, 100.0, {"a": "V"})
    assert used == [f".{f}" for f in FILE_FORMATS]


def test_bearing_datasets_rows_carry_each_channel_unit(made):
    """The tacho is volts, not an acceleration."""
    df = export_mod.bearing_datasets_frame(made, channels=["accel_1b1_y", "tacho"])
    assert dict(zip(df["channel"], df["unit"])) == {"accel_1b1_y": "m/s^2", "tacho": "V"}


# ---------------------------------------------------------------------- windowed Parquet
def test_windowed_parquet_holds_the_windows_of_to_arrays(made, tmp_path):
    import pyarrow.parquet as pq

    ds = load(made)
    path = tmp_path / "w.parquet"
    res = ds.to_parquet(path, window=128, hop=64, batch_records=1, seed=0,
                        fractions=(0.5, 0.25, 0.25))
    X, y, groups = ds.to_arrays(window=128, hop=64)
    df = pd.read_parquet(path)
    assert len(df) == res["rows"] == len(X) and res["row_groups"] == 4
    assert pq.ParquetFile(path).metadata.num_row_groups == 4      # bounded memory
    assert list(df["label"]) == list(y) and list(df["record_id"]) == list(groups)
    for k, c in enumerate(MEASURABLE):
        got = np.stack(df[c].to_numpy())
        assert got.dtype == np.float32
        np.testing.assert_array_equal(got, X[:, k])
    assert "dte_um" not in df.columns
    assert (df.groupby("group")["split"].nunique() == 1).all()    # a group in one split
    assert set(df["split"]) <= {"train", "val", "test"}
    row = ds.manifest.set_index("record_id").loc[df["record_id"].iloc[-1]]
    assert df["speed_rpm"].iloc[-1] == pytest.approx(row["speed_rpm"])
    assert df["fs_hz"].iloc[0] == pytest.approx(25600.0)
    np.testing.assert_allclose(df["start_s"].iloc[:3], np.arange(3) * 64 / 25600.0)
    meta = json.loads(pq.read_schema(path).metadata[b"cmsim"])
    assert meta["units"] == {"accel_1b1_y": "m/s²", "tacho": "V"} and meta["hop"] == 64


def test_windowed_parquet_loads_with_huggingface_datasets(made, tmp_path):
    hf = pytest.importorskip("datasets")
    if not hasattr(hf, "load_dataset"):            # the repo's datasets/ folder, not the library
        pytest.skip("HuggingFace datasets is not installed")
    ds = load(made)
    path = tmp_path / "w.parquet"
    ds.to_parquet(path, window=128)
    X, y, _ = ds.to_arrays(window=128)
    hds = hf.load_dataset("parquet", data_files=str(path), split="train",
                          cache_dir=str(tmp_path / "hf"))
    assert hds.num_rows == len(X) and list(hds["label"]) == list(y)
    np.testing.assert_array_equal(np.asarray(hds[0]["accel_1b1_y"], np.float32), X[0, 0])


def test_the_split_depends_on_the_group_alone():
    groups = [f"{i:06d}" for i in range(2000)]
    splits = [split_of(g, seed=7) for g in groups]
    assert splits == [split_of(g, seed=7) for g in reversed(groups)][::-1]
    share = {s: splits.count(s) / len(splits) for s in ("train", "val", "test")}
    assert share["train"] == pytest.approx(0.8, abs=0.04)
    assert share["test"] == pytest.approx(0.1, abs=0.03)
    assert splits != [split_of(g, seed=8) for g in groups]
    with pytest.raises(ParameterError, match="fractions"):
        split_of("a", fractions=(1, 1))


def test_dataset_exported_as_parquet_is_the_windowed_layout(made, tmp_path):
    res = export(made, tmp_path / "out", "parquet", window=256, group_by="rig_name")
    df = pd.read_parquet(tmp_path / "out" / "windows.parquet")
    assert res["windows"]["rows"] == len(df) and res["windows"]["path"].startswith(
        str(tmp_path / "out"))
    assert df["group"].nunique() == 1 and df["split"].nunique() == 1   # one rig, one split
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["windows.parquet"]


def test_the_windowed_folder_loads_as_a_folder(made, tmp_path):
    """Issue 48: a labels.csv inside the windowed folder broke every folder loader; the
    folder holds Parquet alone and loads whole with pandas and pyarrow (and HuggingFace's
    parquet loader, where installed), every window with its record's labels."""
    import pyarrow.dataset as pds

    export(made, tmp_path / "out", "parquet", window=256)
    one = pd.read_parquet(tmp_path / "out" / "windows.parquet")
    whole = pd.read_parquet(tmp_path / "out")
    assert len(whole) == len(one) and list(whole["label"]) == list(one["label"])
    assert pds.dataset(tmp_path / "out").to_table().num_rows == len(one)
    labels = load(made).manifest.set_index("record_id")["fault_label"]
    assert all(whole["label"] == labels.loc[whole["record_id"]].to_numpy())
    hf = pytest.importorskip("datasets")
    if not hasattr(hf, "load_dataset"):            # the repo's datasets/ folder, not the library
        pytest.skip("HuggingFace datasets is not installed")
    hds = hf.load_dataset("parquet", data_dir=str(tmp_path / "out"), split="train",
                          cache_dir=str(tmp_path / "hf"))
    assert hds.num_rows == len(one)


def test_export_folders_have_the_permissions_of_mkdir(made, tmp_path):
    """An export folder was created 0700 (mkdtemp's mode, kept through the rename): other
    users of a shared machine could not read it. It gets 0777 less the umask, as mkdir."""
    import os
    mask = os.umask(0o022)
    try:
        export(made, tmp_path / "out", "npz")
    finally:
        os.umask(mask)
    assert (tmp_path / "out").stat().st_mode & 0o777 == 0o755
