"""Sweep report: HTML with relative links to PNGs that exist, are non-trivial, and are
reproduced from the run files alone.

Test tier: behaviour contracts on a tiny sweep (2 torques × 0.05 s).
"""

import json
import re
import shutil

import numpy as np
import pytest

from cmsim.cli import main
from cmsim.datasets import PARQUET_NAME, RECORDS_DIR, DatasetSpec, generate_dataset
from cmsim.errors import ParameterError
from cmsim.datasets.report import build_report

TINY = DatasetSpec([("speed_rpm", [1000.0]), ("torque_nm", [10.0, 100.0])], duration_s=0.05,
                   seed=7)


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "tiny"
    generate_dataset(TINY, out, workers=2)
    return out


@pytest.fixture(scope="module")
def report(sweep_dir):
    return build_report(sweep_dir)


def _pixels(path):
    from matplotlib.image import imread
    return imread(path)


def test_html_references_every_png_and_each_is_non_trivial(report, sweep_dir):
    page = (sweep_dir / "report.html").read_text(encoding="utf-8")
    srcs = re.findall(r'<img src="([^"]+)"', page)
    assert sorted(srcs) == sorted(report.figures)
    assert {"dte.png", "waterfall_dte_um.png", "waterfall_F_1b1_loa.png",
            "waterfall_F_1b1_oloa.png", "gmf_harmonics.png", "orbits.png"} <= set(srcs)
    for name in srcs:
        assert "/" not in name and not name.startswith("http")   # relative, same directory
        path = sweep_dir / name
        assert path.stat().st_size > 5_000, name
        img = _pixels(path)
        assert img.shape[0] > 300 and img.shape[1] > 600, name
        assert float(np.var(img[..., :3])) > 1e-3, name         # not blank
    assert "http://" not in page and "https://" not in page    # no external assets
    assert "<script" not in page


def test_header_tables_and_dominant_harmonic(report, sweep_dir):
    page = (sweep_dir / "report.html").read_text(encoding="utf-8")
    for text in ("Fernandez-del-Rincon et al. 2016", "1000 rpm", "466.67 Hz", "Torque [N·m]",
                 "2GMF", "Labelled peaks", "dB re carrier"):
        assert text in page, text
    assert report.sweep_axis == "torque_nm"
    assert report.dominant_signal == "F_1b1_loa"
    dom = {r["torque_nm"]: r["dominant_gmf_harmonic"] for r in report.runs}
    assert dom == {10.0: 2, 100.0: 5}            # the paper's statement, even at 20 Hz bins
    t = report.timing_s
    assert t["total"] >= t["plot"] > 0 and t["spectra"] > 0
    assert t["integration"] > 0


def test_regenerating_from_the_run_files_alone_reproduces_the_report(report, sweep_dir,
                                                                       tmp_path):
    bare = tmp_path / "bare"
    shutil.copytree(sweep_dir / RECORDS_DIR, bare / RECORDS_DIR)    # no manifest, no report
    again = build_report(bare)
    assert again.figures == report.figures
    assert [r["dominant_gmf_harmonic"] for r in again.runs] == \
        [r["dominant_gmf_harmonic"] for r in report.runs]
    for name in report.figures:
        np.testing.assert_array_equal(_pixels(bare / name), _pixels(sweep_dir / name))
    strip = re.compile(r"cmsim sweep report — \w+|cmsim report \w+")
    assert strip.sub("", (bare / "report.html").read_text()) == \
        strip.sub("", (sweep_dir / "report.html").read_text())


def test_report_errors(sweep_dir, tmp_path):
    with pytest.raises(ParameterError, match="does not exist"):
        build_report(tmp_path / "nowhere")
    with pytest.raises(ParameterError, match="no finished runs"):
        build_report(tmp_path)
    with pytest.raises(ParameterError, match=r"not in .*available"):
        build_report(sweep_dir, ["F_9b9_loa"])
    with pytest.raises(ParameterError, match="top_n"):
        build_report(sweep_dir, top_n=0)


def test_cli_report_json(sweep_dir, capsys):
    assert main(["report", str(sweep_dir), "--signal", "F_1b1_loa", "--top", "3",
                 "--max-hz", "2500", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    for key in ("html", "figures", "runs", "load_s", "spectra_s", "plot_s", "total_s"):
        assert key in res
    assert "waterfall_F_1b1_loa.png" in res["figures"]
    assert "waterfall_dte_um.png" not in res["figures"]
    assert [r["dominant_gmf_harmonic"] for r in res["runs"]] == [2, 5]
    assert main(["report", str(sweep_dir / PARQUET_NAME), "--json"]) == 2


def test_loss_breakdown_of_a_sweep_whose_runs_carry_it(tmp_path, capsys):
    """A sweep made with ``--losses``: the report draws the loss power by source and the
    efficiency of each run, and tabulates them with each run's power-balance closure; a
    sweep without losses has no such section (the tiny sweep above)."""
    out = tmp_path / "lossy"
    assert main(["sweep", "--speed-rpm", "1000", "3000", "--torque-nm", "50", "--duration-s",
                 "0.05", "--losses", "--out", str(out), "--workers", "1", "--json"]) == 0
    capsys.readouterr()
    res = build_report(out)
    assert "losses.png" in res.figures
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "<h2>Power losses</h2>" in page
    rows = re.findall(r"<tr><td[^>]*>(\d{3}_[^<]*)</td>(.*?)</tr>",
                      page.split("<h2>Power losses</h2>")[1].split("</table>")[0])
    assert len(rows) == 2
    for _, cells in rows:
        values = re.findall(r"<td[^>]*>([^<]*)</td>", cells)
        efficiency, closure = float(values[-2]), float(values[-1])
        assert 95.0 < efficiency < 100.0 and closure < 1.0
    img = _pixels(out / "losses.png")
    assert img.shape[0] > 200 and np.std(img) > 0.05


def test_a_dataset_of_sensor_channels_is_refused_by_name(tmp_path):
    """The report draws full runs; a dataset that kept sensor channels only says so."""
    spec = DatasetSpec([("speed_rpm", [1000.0])], channels=["accel_1b1_y"], fs_hz=25_600.0,
                       duration_s=0.02)
    generate_dataset(spec, tmp_path / "ds", workers=1)
    with pytest.raises(ParameterError, match="sensor channels"):
        build_report(tmp_path / "ds")


def test_no_loss_section_without_losses(report, sweep_dir):
    assert "losses.png" not in report.figures
    assert "Power losses" not in (sweep_dir / "report.html").read_text(encoding="utf-8")
