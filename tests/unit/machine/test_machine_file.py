"""The machine file keeps the baseline's samples and the signature library (cmsim.machine).

Tier: structure. What a machine writes it reads back (the samples to float32, the library's
tables to float32); a damaged or cut file is refused naming what is wrong, never read into a
machine that judges records with part of its baseline.
"""

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.machine import Background, Machine, TransferPath
from cmsim.machine.baseline import Baseline
from cmsim.machine.library import SignatureEntry, SignatureLibrary, _pack, _unpack
from cmsim.rig import OperatingPoint, Rig


def _library(m=3):
    rng = np.random.default_rng(0)
    return SignatureLibrary(
        names=tuple(f"f{i}" for i in range(m)), mean=rng.standard_normal(m),
        spread=np.abs(rng.standard_normal(m)), realisation=np.full(m, np.nan),
        run_spread=np.arange(m, dtype=float),
        entries=(SignatureEntry("noise", None, "documented", "noise_ratio", (0.2, 1.0),
                                rng.standard_normal((2, m))),
                 SignatureEntry("bearing_inner_race", "1b1", "line contact; path x0.3",
                                "size_m", (1e-4, 3e-4, 1e-3), rng.standard_normal((3, m)))),
        segment_s=0.5, segments=8, speed_rpm=1797.0, torque_nm=0.0, radial_load_n=98.0,
        seed=4, n_sizes=3)


def _machine():
    f = (0.0, 6000.0)
    rng = np.random.default_rng(1)
    return Machine(name="m", rig=Rig.paper_2016(), channel="DE", model_signal="accel_1b1_y",
                   fs_hz=12000.0, op=OperatingPoint(1797.0, 10.0),
                   path=TransferPath("F_1b1_y", f, (1e-3, 2e-3), "g"),
                   background=Background(f, (1e-6, 1e-6)), unit="g", unit_scale=9.80665,
                   spread={"f0": (0.0, 1.0)}, fit_quality={"chi2_per_feature": 1.0},
                   baseline=Baseline((rng.standard_normal(24000),
                                      rng.standard_normal(12000)), 12000.0),
                   library=_library())


def test_the_baseline_and_library_round_trip(tmp_path):
    m = _machine()
    m.save(tmp_path / "m.toml")
    back = Machine.load(tmp_path / "m.toml")
    for a, b in zip(m.baseline.records, back.baseline.records):
        assert np.array_equal(a, b)                          # float32 both ways
    lib, got = m.library, back.library
    assert got.names == lib.names and got.segments == lib.segments and got.seed == lib.seed
    assert got.n_sizes == 3          # what a calibration again at another rate builds anew
    assert np.allclose(got.mean, lib.mean.astype(np.float32), rtol=0, atol=0)
    assert np.isnan(got.realisation).all()
    assert np.array_equal(got.run_spread, np.arange(3.0))
    for a, b in zip(lib.entries, got.entries):
        assert (a.cause, a.component, a.variant, a.values) == (b.cause, b.component,
                                                                b.variant, b.values)
        assert np.array_equal(a.features.astype(np.float32), b.features)


def test_a_machine_file_cut_before_its_baseline_is_refused(tmp_path):
    m = _machine()
    m.save(tmp_path / "m.toml")
    text = (tmp_path / "m.toml").read_text()
    cut = text[:text.index("[baseline]")]
    (tmp_path / "cut.toml").write_text(cut)
    with pytest.raises(ParameterError, match="lacks 'baseline'"):
        Machine.load(tmp_path / "cut.toml")


@pytest.mark.parametrize("table", ["machine", "library"])
def test_a_segment_length_edited_to_nan_is_refused_by_name(tmp_path, table):
    """A machine file edited by hand: a segment length that is no length is refused by its
    table and key (the library's made compare fail as an internal error, the machine's was
    read as it was)."""
    _machine().save(tmp_path / "m.toml")
    text = (tmp_path / "m.toml").read_text()
    head = text.index(f"[{table}]")
    at = text.index("segment_s = ", head)
    end = text.index("\n", at)
    (tmp_path / "nan.toml").write_text(text[:at] + "segment_s = nan" + text[end:])
    with pytest.raises(ParameterError, match=rf'\[{table}\] "segment_s" must be .* got nan'):
        Machine.load(tmp_path / "nan.toml")


def test_a_damaged_baseline_record_is_refused(tmp_path):
    m = _machine()
    m.save(tmp_path / "m.toml")
    text = (tmp_path / "m.toml").read_text()
    i = text.index("float32_zlib_base64 = \"") + len("float32_zlib_base64 = \"") + 40
    flipped = text[:i] + ("A" if text[i] != "A" else "B") + text[i + 1:]
    (tmp_path / "bad.toml").write_text(flipped)
    with pytest.raises(ParameterError, match="damaged"):
        Machine.load(tmp_path / "bad.toml")


def test_a_version_one_machine_reads_without_baseline():
    d = _machine().to_dict()
    d["format_version"] = 1
    for k in ("baseline", "library"):
        d.pop(k)
    m = Machine.from_dict(d)
    assert m.baseline is None and m.library is None


def test_baseline_segments_stay_within_each_record_and_a_piece_within_one():
    b = _machine().baseline
    segs = b.segments(0.5)
    assert segs.shape == (6, 6000)          # 4 + 2: none across the two records
    assert np.array_equal(segs[4], b.records[1][:6000])
    assert b.segments(0.5, 3).shape[0] == 3
    piece = b.piece(18000, np.random.default_rng(0))
    assert any(np.array_equal(piece, r[s:s + 18000]) for r in b.records
               for s in range(0, max(r.size - 18000 + 1, 0)))
    with pytest.raises(ParameterError, match="longer than the machine's longest"):
        b.piece(30000, np.random.default_rng(0))


def test_a_baseline_with_nan_is_refused():
    with pytest.raises(ParameterError, match="NaN"):
        Baseline((np.array([0.0, np.nan, 1.0]),), 1000.0)


def test_a_library_written_before_its_size_count_was_kept_reads_none():
    d = _library().to_dict()
    del d["n_sizes"]
    assert SignatureLibrary.from_dict(d).n_sizes is None
    with pytest.raises(ParameterError, match="n_sizes"):
        SignatureLibrary.from_dict({**_library().to_dict(), "n_sizes": 0})


def test_a_version_one_library_reads_its_realisation_as_its_run_spread():
    """Libraries before the run spread (format 1: the reference's three rows, then the
    entries') read on; a format this cmsim does not know is refused by name."""
    lib = _library()
    d = lib.to_dict()
    rows = _unpack(d["tables_float32_zlib_base64"], (d["rows"], len(lib.names)))
    old = np.delete(rows, 3, axis=0)
    d1 = {**d, "format_version": 1, "rows": old.shape[0], "tables_float32_zlib_base64": _pack(old)}
    got = SignatureLibrary.from_dict(d1)
    assert np.array_equal(got.run_spread, got.realisation, equal_nan=True)
    assert [np.array_equal(a.features, b.features) for a, b in zip(got.entries,
            SignatureLibrary.from_dict(d).entries)] == [True, True]
    with pytest.raises(ParameterError, match="format_version 3 is not supported"):
        SignatureLibrary.from_dict({**d, "format_version": 3})


@pytest.mark.parametrize("fs_hz, refused", [(12_000.0, False), (25_600.0, False),
                                            (12_904.558781928758, True), (48_828.125, True)])
def test_a_version_2_file_is_read_only_where_its_segments_are_todays(tmp_path, fs_hz, refused):
    """Version-2 files read 0.5-s segments as round(0.5 · fs) samples; cmsim now reads the
    nearest length with no prime factor over 5. Where the two agree (the common rates) the
    file is read as it is; where they do not, its spread and library were read on other
    segments, and it is refused with a request for a new calibration, never used."""
    from dataclasses import replace
    m = replace(_machine(), fs_hz=fs_hz, baseline=Baseline(_machine().baseline.records, fs_hz))
    d = m.to_dict()
    assert d["format_version"] == 3
    d["format_version"] = 2
    if refused:
        with pytest.raises(ParameterError, match="run cmsim calibrate again") as err:
            Machine.from_dict(d)
        assert f"segments of {round(0.5 * fs_hz)} samples" in str(err.value)
    else:
        assert Machine.from_dict(d).fs_hz == fs_hz
