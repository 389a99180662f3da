"""What a dataset run does per record and per resume besides simulating (issue 49): each
record's plan is drawn once, and a resumed directory's manifest is read once.

Test tier: behaviour contracts (no physics): 3 records of 0.02 s, counted calls.
"""

import json

from cmsim.cli import main
from cmsim.datasets import DatasetSpec, generate_dataset

SPEC = {
    "dataset": {"name": "tiny", "records": 3, "seed": 7},
    "rig": {"builtin": "paper_2016"},
    "operating": {"speed_rpm": {"distribution": "uniform", "min": 950.0, "max": 1050.0},
                  "torque_nm": 50.0},
    "faults": {"healthy_share": 0.5,
               "types": [{"type": "tooth_crack", "gear": [1], "depth_m": 1.5e-3}]},
    "nuisances": {"slip": 0.002},
    "sensor": {"channels": ["accel_1b1_y", "tacho"], "fs_hz": 25600.0, "duration_s": 0.02,
               "warmup_s": 0.01},
}


def _counting(monkeypatch, owner, name):
    calls = []
    real = getattr(owner, name)

    def counted(*a, **kw):
        calls.append(a)
        return real(*a, **kw)

    monkeypatch.setattr(owner, name, counted)
    return calls


def test_each_record_is_drawn_once(tmp_path, monkeypatch):
    from cmsim.datasets.manifest import RECORDS_DIR, ROWS_DIR
    from cmsim.datasets.records import run_record

    spec = DatasetSpec.from_dict(SPEC)
    for sub in (RECORDS_DIR, ROWS_DIR):
        (tmp_path / sub).mkdir()
    calls = _counting(monkeypatch, DatasetSpec, "record")
    row = run_record(spec, 1, tmp_path)          # a worker's task of one record
    assert row["status"] == "ok"
    assert len(calls) == 1
    # a dataset run draws the plans in the parent, once, and hands them to the workers
    calls.clear()
    s = generate_dataset(spec, tmp_path / "d", workers=1, start_method="fork")
    assert s.records_written == 3 and len(calls) == 3


def test_a_resume_reads_the_manifest_once(tmp_path, monkeypatch):
    import tomli_w

    from cmsim.datasets import manifest

    spec_file = tmp_path / "tiny.toml"
    spec_file.write_text(tomli_w.dumps(SPEC))
    out = tmp_path / "d"
    assert main(["dataset", str(spec_file), "--out", str(out), "--workers", "1",
                 "--json"]) == 0
    reads = _counting(monkeypatch, manifest, "_read_parquet")
    assert main(["dataset", str(spec_file), "--out", str(out), "--workers", "1",
                 "--json"]) == 0
    assert len(reads) == 1
    # with sidecars left behind (a killed run), still once: they are read, the manifest not
    (out / "rows").mkdir(exist_ok=True)
    row = json.loads(manifest.read_rows(out).iloc[[0]].to_json(orient="records"))[0]
    manifest.write_row(out, row)
    reads.clear()
    assert main(["dataset", str(spec_file), "--out", str(out), "--workers", "1",
                 "--json"]) == 0
    assert len(reads) == 1
    assert not list((out / "rows").glob("*.json"))
