"""``cmsim spectrum``: JSON contract, kinds, plot, and errors naming the parameter.

Test tier: behaviour contracts on one short run (0.2 s of the paper rig at 1000 rpm).
"""

import json

import numpy as np
import pytest

from cmsim.cli import main
from cmsim.dynamics import simulate
from cmsim.errors import ParameterError
from cmsim.rig import OperatingPoint, Rig
from cmsim.run import Run
from cmsim.spectra.run_spectrum import run_spectrum, signal_bearing, signal_unit


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("spectrum") / "run.npz"
    simulate(Rig.paper_2016(), OperatingPoint(1000.0, 10.0), 0.2, seed=3).save(path)
    return path


def cli_json(capsys, argv):
    status = main(argv + ["--json"])
    out = capsys.readouterr().out
    assert len(out.strip().splitlines()) == 1             # exactly one JSON object
    return status, json.loads(out)


def test_json_contract(capsys, run_file):
    status, res = cli_json(capsys, ["spectrum", str(run_file), "--channel", "F_1b1_loa",
                                    "--max-hz", "3000", "--top", "6"])
    assert status == 0
    for key in ("signal", "kind", "resolution_hz", "families", "peaks", "unit", "bearing"):
        assert key in res
    assert (res["signal"], res["kind"], res["unit"], res["bearing"]) == \
        ("F_1b1_loa", "amplitude", "N", "1b1")
    assert res["resolution_hz"] == pytest.approx(5.0)
    assert res["families"]["GMF"] == pytest.approx(466.667, abs=1e-3)
    peaks = res["peaks"]
    assert 1 <= len(peaks) <= 6
    amps = [p["amplitude"] for p in peaks]
    assert amps == sorted(amps, reverse=True)               # largest first
    for p in peaks:
        assert {"frequency_hz", "amplitude", "label", "family", "db_re_carrier"} <= set(p)
        assert 0 < p["frequency_hz"] <= 3000
    assert peaks[0]["label"] == "2GMF"
    assert peaks[0]["frequency_hz"] == pytest.approx(2 * 466.667, abs=5.0)


def test_text_output_and_plot(capsys, run_file, tmp_path):
    png = tmp_path / "s.png"
    assert main(["spectrum", str(run_file), "--max-hz", "2500", "--plot", str(png)]) == 0
    text = capsys.readouterr().out
    assert "frequency_hz" in text and "2GMF" in text and f"wrote {png}" in text
    assert png.stat().st_size > 5_000


def test_other_kinds_and_shaft_two(capsys, run_file):
    status, res = cli_json(capsys, ["spectrum", str(run_file), "--kind", "order", "--top", "3"])
    assert status == 0 and res["kind"] == "order"
    top = res["peaks"][0]
    assert top["order"] == pytest.approx(56.0, abs=0.2)     # 2 × 28 teeth
    assert top["frequency_hz"] == pytest.approx(top["order"] * 1000 / 60)
    status, res = cli_json(capsys, ["spectrum", str(run_file), "--kind", "envelope",
                                    "--band-hz", "1000", "3000", "--top", "3"])
    assert status == 0 and res["band_hz"] == [1000.0, 3000.0]
    status, res = cli_json(capsys, ["spectrum", str(run_file), "--channel", "F_2b1_oloa"])
    assert status == 0 and res["bearing"] == "2b1"
    assert res["families"]["fr"] == pytest.approx(1000 / 60)   # 28:28 gears


@pytest.mark.parametrize("extra, words", [
    (["--channel", "F_9b9_loa"], ["--channel must be one of", "F_1b1_loa", "dte_um"]),
    (["--resolution-hz", "1"], ["record too short", "--resolution-hz=1", "75000 samples"]),
    (["--kind", "order", "--resolution-hz", "1"], ["record too short", "revolutions"]),
    (["--band-hz", "100", "200"], ["--band-hz", "envelope"]),
    (["--kind", "envelope", "--band-hz", "100", "90000"], ["--band-hz", "fs/2"]),
    (["--max-hz", "-3"], ["--max-hz"]),
    (["--top", "0"], ["--top"]),
    (["--bearing", "3b1"], ["bearing must be one of"]),
])
def test_errors_name_the_parameter(capsys, run_file, extra, words):
    status, res = cli_json(capsys, ["spectrum", str(run_file)] + extra)
    assert status == 2
    for w in words:
        assert w in res["error"], (w, res["error"])


def test_missing_file(capsys, tmp_path):
    status, res = cli_json(capsys, ["spectrum", str(tmp_path / "none.npz")])
    assert status == 2 and "does not exist" in res["error"]


def test_library_helpers(run_file):
    run = Run.load(run_file)
    assert signal_unit("F_1b1_x") == "N" and signal_unit("dte_um") == "µm"
    assert signal_unit("theta_2J2") == "rad" and signal_unit("y_2G1") == "m"
    assert signal_bearing("x_2b2", ("1b1", "1b2", "2b1", "2b2")) == "2b2"
    assert signal_bearing("dte", ("1b1", "2b1")) == "1b1"
    s = run_spectrum(run, "theta_1G1", max_hz=1000.0)     # ramp removed by linear detrend
    assert np.all(s.peaks["frequency_hz"] <= 1000.0)
    with pytest.raises(ParameterError, match="kind"):
        run_spectrum(run, "dte", kind="cepstrum")


# ---- any record cmsim writes or reads (issue 26): dataset records, measured recordings
def test_dataset_record(capsys, tmp_path):
    """A record of ``cmsim dataset`` (channels and meta, no ``t``): its first channel, the
    families of its own rig and operating point."""
    spec = tmp_path / "ds.toml"
    spec.write_text('[dataset]\nrecords = 1\n\n[sensor]\nchannels = ["accel_1b1_y"]\n'
                    'duration_s = 0.05\n')
    assert main(["dataset", str(spec), "--out", str(tmp_path / "ds"), "--json"]) == 0
    capsys.readouterr()
    record = next((tmp_path / "ds" / "records").glob("*.npz"))
    status, res = cli_json(capsys, ["spectrum", str(record), "--top", "5"])
    assert status == 0, res
    assert res["signal"] == "accel_1b1_y" and res["unit"] == "m/s²" and res["n_peaks"] >= 1
    assert res["families"]["GMF"] > 0


@pytest.mark.skipif(not (__import__("cmsim.measured", fromlist=["data_root"]).data_root()
                         / "cwru_bearing_12k_de").is_dir(), reason="shared data absent")
def test_measured_recording(capsys):
    """A measured recording with its metadata.json: the compared channel, its bearing's
    families at the record's speed; the envelope spectrum finds the inner-race defect."""
    from cmsim.measured import data_root
    path = data_root() / "cwru_bearing_12k_de" / "IR007_0.npz"
    status, res = cli_json(capsys, ["spectrum", str(path), "--kind", "envelope",
                                    "--max-hz", "500", "--top", "5"])
    assert status == 0, res
    assert res["signal"] == "DE" and res["bearing"] == "1b1"
    bpfi = res["families"]["BPFI"]
    assert bpfi == pytest.approx(162.19, rel=1e-3)
    assert any(abs(p["frequency_hz"] - bpfi) < 1.0 for p in res["peaks"]), res["peaks"]


@pytest.mark.skipif(not (__import__("cmsim.measured", fromlist=["data_root"]).data_root()
                         / "spectraquest_gearbox_gfd").is_dir(), reason="shared data absent")
def test_a_gearbox_with_undocumented_bearings_names_no_bearing_family(capsys):
    """SpectraQuest's metadata documents the teeth and no bearing: the model rig's bearings
    are the paper rig's, an assumption, so no peak is named after them (three mesh
    sidebands read "4GMF-1BPF" from the paper's 209 bearing); the gear and shaft families
    stay."""
    from cmsim.measured import data_root
    path = data_root() / "spectraquest_gearbox_gfd" / "h30hz0.npz"
    status, res = cli_json(capsys, ["spectrum", str(path), "--top", "12"])
    assert status == 0, res
    assert res["bearing"] is None and set(res["families"]) == {"GMF", "fr", "fr2"}, \
        res["families"]
    assert res["families"]["fr2"] == pytest.approx(30.0 * 32 / 80)   # the output shaft
    assert not any("BP" in p["label"] or "BSF" in p["label"] or "FTF" in p["label"]
                   for p in res["peaks"]), res["peaks"]
    assert any(p["label"] == "4GMF" for p in res["peaks"]), res["peaks"]


def test_order_spectrum_of_a_run_up_follows_its_tacho(capsys, tmp_path):
    """A run-up's mesh stays at order 28 (the 28-tooth pinion) when the angle comes from the
    run's tacho; at the nominal speed it would smear over 1.5x the orders."""
    path = tmp_path / "runup.npz"
    main(["simulate", "--speed-rpm", "600", "--ramp-to-rpm", "900", "--torque-nm", "50",
          "--duration-s", "0.6", "--sensors", "--out", str(path)])
    capsys.readouterr()
    status, res = cli_json(capsys, ["spectrum", str(path), "--kind", "order", "--top", "5"])
    assert status == 0 and res["angle_from"] == "tacho"
    gmf = [p for p in res["peaks"] if p["family"] == "GMF" and p["m"] == 0 and p["n"] == 0]
    assert len(gmf) >= 2                      # mesh harmonics stand out, at their orders
    assert all(p["order"] == pytest.approx(28.0 * p["k"], abs=0.05) for p in gmf)
    assert main(["spectrum", str(path), "--kind", "order"]) == 0
    out = capsys.readouterr().out
    assert "orders (angle from the tacho)" in out and "GMF 28.000" in out
    assert out.splitlines()[1].split()[0] == "order"


def test_signal_is_the_deprecated_name_of_channel(capsys, run_file):
    """--signal still works, as --channel, with a warning that it is deprecated (every
    other command calls it --channel)."""
    status, res = cli_json(capsys, ["spectrum", str(run_file), "--signal", "F_2b1_oloa"])
    assert status == 0 and res["signal"] == "F_2b1_oloa"
    assert any("--signal is deprecated" in w for w in res["warnings"]), res["warnings"]


def test_a_relative_record_is_found_under_cmsim_data(capsys, run_file, monkeypatch):
    """spectrum, like compare, looks a relative record up under $CMSIM_DATA."""
    monkeypatch.setenv("CMSIM_DATA", str(run_file.parent))
    monkeypatch.chdir(run_file.parent.parent)
    status, res = cli_json(capsys, ["spectrum", run_file.name])
    assert status == 0 and res["n_peaks"] > 0, res


def test_labels_of_a_measured_record_allow_for_its_speed_and_slip(capsys):
    """Issue 48: the BPFO comb of MFPT's outer-race record (80.1 and 160.1 Hz, 1 % under
    its nominal-speed values) was "?" with a one-bin tolerance; it is labelled within the
    stated speed's uncertainty and the bearing's slip (the record's speed_uncertainty and
    bearing_slip)."""
    from cmsim.measured import data_root
    path = data_root() / "mfpt_bearing" / "OR_vload1_25lb.npz"
    if not path.is_file():
        pytest.skip("shared data absent")
    status, res = cli_json(capsys, ["spectrum", str(path), "--kind", "envelope", "--top",
                                    "3", "--max-hz", "400"])
    assert status == 0
    top = {round(p["frequency_hz"]): p["label"] for p in res["peaks"]}
    assert top[80] in ("1BPF", "1BPFO") and top[160] in ("2BPF", "2BPFO"), top
