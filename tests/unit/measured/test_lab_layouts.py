"""Recordings as labs write them are read right, or refused with what to fix (issue 17).

Test tier: behaviour contracts on files written here. One known signal — a 1.0-g line at
1234.5 Hz and a 0.3-g shaft line, 2 s at 12 kHz — is written the ways a DAQ program or a
lab's script writes it (found by a probe of honest lab files, 2026-12-02), and read back
through :func:`cmsim.measured.read_run`: the channel compared, its rate and its level.
"""

import struct

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.measured import read_run

FS, N = 12_000, 24_000
T = np.arange(N) / FS
X = np.sin(2 * np.pi * 1234.5 * T) + 0.3 * np.sin(2 * np.pi * 29.95 * T)


def _line(x, fs=FS, f0=1234.5):
    """Amplitude of the line at f0 (Hann, coherent gain removed)."""
    w = np.hanning(x.size)
    spec = np.abs(np.fft.rfft(x * w)) * 2 / w.sum()
    f = np.fft.rfftfreq(x.size, 1 / fs)
    return float(spec[np.abs(f - f0) < 3].max())


def _read(path, **kw):
    run, channel = read_run(path, speed_rpm=1797.0, trust_metadata=True, **kw)
    return run, channel


@pytest.mark.parametrize("name, write", [
    ("labview.csv", lambda p: p.write_text("X_Value,acc1\n" + "".join(
        f"{a:.9g},{b:.9g}\n" for a, b in zip(T, X)))),
    ("time_channel.npz", lambda p: np.savez(p, time=T, vib=X, fs_hz=np.float64(FS))),
    ("time_column.mat", lambda p: __import__("scipy.io").io.savemat(
        p, {"data": np.column_stack([T, X])})),
])
def test_a_time_base_is_never_the_channel_compared_by_default(tmp_path, name, write):
    """A channel that rises at every sample is a clock: the default channel is the
    vibration beside it (the first by name was LabVIEW's X_Value, a time ramp read as a
    1.14-Hz line in g)."""
    path = tmp_path / name
    write(path)
    run, channel = _read(path, fs_hz=FS, unit="g")
    assert channel in ("acc1", "vib", "data_1")
    assert _line(run[channel]) == pytest.approx(1.0, abs=0.01)


def test_spectrum_s_channel_reaches_the_reader(tmp_path, capsys):
    """``cmsim spectrum --channel`` chooses the channel every check runs on: a dead channel
    beside it (a constant AI0) no longer refuses the file."""
    import json

    from cmsim.cli import main

    path = tmp_path / "daq.csv"
    path.write_text("time [s],AI0 [V],AI1 [g]\n" + "".join(
        f"{a:.9g},0,{b:.9g}\n" for a, b in zip(T, X)))
    status = main(["spectrum", str(path), "--speed-rpm", "1797", "--channel", "AI1",
                   "--json"])
    out = json.loads(capsys.readouterr().out)
    assert status == 0, out
    assert out["signal"] == "AI1" and out["unit"] == "g"
    assert out["peaks"][0]["frequency_hz"] == pytest.approx(1234.5, abs=0.5)


def test_an_npz_states_its_rate_in_a_one_value_array_of_a_rate_name(tmp_path):
    """``fs_hz`` of shape (1,) is the rate (it was ignored, so a contradicting --fs-hz was
    taken); ``fs`` is a rate too (it was refused as a channel of shape ()); a plain-text
    ``units`` is every channel's unit (it was refused as damaged JSON)."""
    np.savez(tmp_path / "a.npz", acc=X, fs_hz=np.array([float(FS)]))
    with pytest.raises(ParameterError,
                       match="fs_hz\" array says sample rate 12000 Hz but fs_hz says 25600 Hz"):
        _read(tmp_path / "a.npz", fs_hz=25_600.0)
    np.savez(tmp_path / "b.npz", acc=X, fs=np.float64(FS), units=np.array("g"))
    run, channel = _read(tmp_path / "b.npz")
    assert channel == "acc" and run.fs_hz == FS
    assert _line(run[channel]) == pytest.approx(1.0, abs=0.01)


def _wav24(path, counts):
    """A 24-bit PCM WAV of one channel (what a DAQ's recorder writes)."""
    data = counts.astype("<i4").view(np.uint8).reshape(-1, 4)[:, :3].tobytes()
    fmt = struct.pack("<HHIIHH", 1, 1, FS, FS * 3, 3, 24)
    body = (b"WAVE" + b"fmt " + struct.pack("<I", len(fmt)) + fmt + b"data"
            + struct.pack("<I", len(data)) + data + (b"\0" if len(data) & 1 else b""))
    path.write_bytes(b"RIFF" + struct.pack("<I", len(body)) + body)


def test_a_24_bit_wav_is_read_in_its_stored_counts(tmp_path):
    """scipy gives 24-bit samples left-justified in 32 bits; a calibration is stated per
    stored 24-bit count (full scale 2^23), so the level was 256 times too high."""
    c = 1.05 * np.abs(X).max() / (2 ** 23 - 1)
    _wav24(tmp_path / "r.wav", np.round(X / c))
    run, channel = _read(tmp_path / "r.wav", unit="g", calibration=c)
    assert _line(run[channel]) == pytest.approx(1.0, abs=0.01)


def test_one_column_with_decimal_commas_is_one_channel(tmp_path):
    """A one-column European CSV: the comma between digits is the decimal comma, not a
    separator (sniffed as one, it split every number: 1975 Hz at 8e7 g)."""
    (tmp_path / "r.csv").write_text("acc1 [g]\n" + "".join(
        f"{v:.9g}\n".replace(".", ",") for v in X))
    run, channel = _read(tmp_path / "r.csv", fs_hz=FS)
    assert channel == "acc1" and run[channel].size == N
    assert _line(run[channel]) == pytest.approx(1.0, abs=0.01)


def test_a_header_less_sample_index_column_states_no_rate(tmp_path):
    """A first column counting the samples (0, 1, 2, ...) is their index, not a time in
    seconds: it read as a 1-Hz rate and refused the --fs-hz the user stated."""
    (tmp_path / "r.csv").write_text("".join(f"{i},{v:.9g}\n" for i, v in enumerate(X)))
    run, channel = _read(tmp_path / "r.csv", fs_hz=FS, unit="g")
    assert run.fs_hz == FS and run[channel].size == N
    assert _line(run[channel]) == pytest.approx(1.0, abs=0.01)
    (tmp_path / "t.csv").write_text("".join(f"{a:.9g},{v:.9g}\n" for a, v in zip(T, X)))
    run, channel = _read(tmp_path / "t.csv", unit="g")       # a time in s still states it
    assert run.fs_hz == pytest.approx(FS, rel=1e-6)


@pytest.mark.parametrize("name, text, encoding", [
    ("units_row.csv", "time,acc1\ns,g\n" + "".join(f"{a:.9g},{b:.9g}\n" for a, b in zip(T, X)),
     "utf-8"),
    ("preamble.csv", "# Device: NI 9234\n# Sample rate: 12000 Hz\ntime [s],acc1 [g]\n"
     + "".join(f"{a:.9g},{b:.9g}\n" for a, b in zip(T, X)), "utf-8"),
    ("windows.csv", "time [s];acc1 [m/s²]\n" + "".join(
        f"{a:.9g};{9.80665 * b:.9g}\n".replace(".", ",") for a, b in zip(T, X)), "cp1252"),
    ("trailing.csv", "Time [sec],acc1 [g],\n" + "".join(
        f"{a:.9g},{b:.9g},\n" for a, b in zip(T, X)), "utf-8"),
    ("micro.csv", "time [us],acc1 [g]\n" + "".join(
        f"{1e6 * a:.9g},{b:.9g}\n" for a, b in zip(T, X)), "utf-8"),
])
def test_a_daq_program_s_csv_layouts_are_read(tmp_path, name, text, encoding):
    """A units row under the header, a preamble of # lines, a Windows-1252 file (m/s² in
    one byte) with decimal commas, a separator ending every line, time in sec or µs: each
    was refused (as damaged, or its time column as a channel in an unknown unit)."""
    (tmp_path / name).write_bytes(text.encode(encoding))
    run, channel = _read(tmp_path / name)
    assert channel == "acc1" and run.fs_hz == pytest.approx(FS, rel=1e-6)
    level = 9.80665 if name == "windows.csv" else 1.0        # m/s² there, g elsewhere
    assert _line(run[channel]) == pytest.approx(level, rel=0.01)
    assert list(run.signals) == ["acc1"]


def test_integer_counts_without_a_calibration_are_read_with_a_warning(tmp_path):
    """A converter's int16 counts stated in g with no calibration read as 1 g a count
    (15 780 "g" for this signal): said, not silent; with the calibration, not said."""
    import warnings

    from cmsim.errors import RecordWarning

    c = 1.05 * np.abs(X).max() / 32767
    np.savez(tmp_path / "r.npz", acc=np.round(X / c).astype(np.int16), fs_hz=np.float64(FS))
    with pytest.warns(RecordWarning, match="'acc' holds integer counts .* 1 g"):
        _read(tmp_path / "r.npz", unit="g")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RecordWarning)
        run, channel = _read(tmp_path / "r.npz", unit="g", calibration=c)
    assert _line(run[channel]) == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize("decimals", [4, 5])
def test_time_stamps_printed_coarser_than_a_step_give_the_rate(tmp_path, decimals):
    """Time stamps printed to 0.1 ms at 12 kHz (steps of 0 and 0.0001 s) are rounding, not a
    gap: they were refused as "not evenly spaced"; the rate is the one the stamps pin
    (12 kHz, not 11999.7). A dropped sample among them is still refused, naming it."""
    fmt = f"{{:.{decimals}f}},{{:.9g}}\n"
    (tmp_path / "r.csv").write_text("time,acc1 [g]\n" + "".join(
        fmt.format(a, b) for a, b in zip(T, X)))
    run, channel = _read(tmp_path / "r.csv")
    assert run.fs_hz == FS and _line(run[channel]) == pytest.approx(1.0, abs=0.01)
    gap = np.delete(np.arange(N + 1) / FS, 5000)
    (tmp_path / "gap.csv").write_text("time,acc1 [g]\n" + "".join(
        fmt.format(a, b) for a, b in zip(gap, X)))
    with pytest.raises(ParameterError, match="not evenly spaced .step 4999 from 0.416"):
        _read(tmp_path / "gap.csv")


def test_a_coarsely_printed_clock_is_never_the_channel_compared(tmp_path):
    """LabVIEW's X_Value printed to 0.1 ms repeats a stamp now and then: it was taken for
    the vibration (not rising at every sample) and its ramp read as the record."""
    (tmp_path / "r.csv").write_text("X_Value,acc1\n" + "".join(
        f"{a:.4f},{b:.9g}\n" for a, b in zip(T, X)))
    run, channel = _read(tmp_path / "r.csv", fs_hz=FS, unit="g")
    assert channel == "acc1" and _line(run[channel]) == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize("unit, factor", [("ms", 1e3), ("µs", 1e6)])
def test_a_header_less_time_column_in_ms_is_said_not_read_as_seconds(tmp_path, unit, factor):
    """A header-less first column of the time in ms read as seconds: a 12-Hz record, its
    1234.5-Hz line at 1.2 Hz, silently. Under the least rate of a vibration record it is
    read in ms (or µs), and the correction is said."""
    from cmsim.errors import RecordWarning

    (tmp_path / "r.csv").write_text("".join(
        f"{factor * a:.6f},{b:.9g}\n" for a, b in zip(T, X)))
    with pytest.warns(RecordWarning, match=f"read as the time in {unit}: 12000 Hz"):
        run, channel = _read(tmp_path / "r.csv", unit="g")
    assert run.fs_hz == FS and _line(run[channel]) == pytest.approx(1.0, abs=0.01)
    assert any(f"time in {unit}" in w for w in run.meta["warnings"])


def test_time_stamps_printed_coarser_than_two_samples_leave_the_rate_to_be_stated(tmp_path):
    """Stamps printed to 1 ms at 12 kHz cannot give the rate nor show a gap: the file was
    refused whatever rate the user gave; now it states none, says why, and reads at the
    rate given (refused without one, the reason in the message)."""
    from cmsim.errors import RecordWarning

    (tmp_path / "r.csv").write_text("time,acc1 [g]\n" + "".join(
        f"{a:.3f},{b:.9g}\n" for a, b in zip(T, X)))
    with pytest.warns(RecordWarning, match="printed to 0.001 s, coarser than two samples"):
        run, channel = _read(tmp_path / "r.csv", fs_hz=FS)
    assert run.fs_hz == FS and _line(run[channel]) == pytest.approx(1.0, abs=0.01)
    with pytest.raises(ParameterError, match="states no sample rate .time 'time' is printed"), \
            pytest.warns(RecordWarning):
        _read(tmp_path / "r.csv")


def test_a_mat_struct_s_fields_are_channels_and_its_rate(tmp_path):
    """A lab script's ``rec.acc`` with ``rec.fs`` (and ``rec.units``), or a struct per
    channel beside a top-level ``fs``: the fields were skipped ("states no sample rate", then
    no channel); they are read as ``struct.field``."""
    from scipy.io import savemat

    savemat(tmp_path / "a.mat", {"rec": {"acc": X, "fs": float(FS), "units": {"acc": "g"}}})
    run, channel = _read(tmp_path / "a.mat")
    assert channel == "rec.acc" and run.fs_hz == FS
    assert _line(run[channel]) == pytest.approx(1.0, abs=0.01)
    savemat(tmp_path / "b.mat", {"ch1": {"y": 2 * X}, "ch2": {"y": X}, "fs": float(FS)})
    run, channel = _read(tmp_path / "b.mat", channel="ch2.y", unit="g")
    assert run.fs_hz == FS and _line(run[channel]) == pytest.approx(1.0, abs=0.01)
