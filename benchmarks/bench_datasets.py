"""Dataset generator benchmarks (issue 11; figures, not timed tests).

python benchmarks/bench_datasets.py [--records N] [--out DIR]

* records per hour for 1-s records (gear_faults spec, paper rig) on 1 and 2 workers (three
  interleaved pairs, the fastest of each), the share of the workers' wall time spent in the
  integration, and the 1 -> 2 speed-up (of the fastest runs, and of each pair);
* memory (RSS) of each worker sampled over the run: first and last reading;
* resume of an almost-finished 100 000-record dataset (synthetic manifest, empty files);
* per standard spec: seconds and bytes per record on a sample -> estimated time and disk size.
"""

import argparse
import copy
import json
import os
import shutil
import tempfile
import threading
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _rss_children(pid):
    out = {}
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            status = (d / "status").read_text()
        except OSError:
            continue
        fields = dict(line.split(":", 1) for line in status.splitlines() if ":" in line)
        if fields.get("PPid", "").strip() == str(pid):
            out[int(d.name)] = int(fields.get("VmRSS", "0 kB").split()[0]) / 1024
    return out


def bench_throughput_pairs(records, tmp, pairs=3):
    """1 and 2 workers interleaved ``pairs`` times (the load of a shared machine drifts);
    each side's fastest run, and the speed-up of the fastest runs."""
    runs = {1: [], 2: []}
    for k in range(pairs):
        for w in (1, 2):
            runs[w].append(bench_throughput(records, w, Path(tmp) / f"pair{k}"))
    best = {w: min(r, key=lambda x: x["wall_s"]) for w, r in runs.items()}
    return best[1], best[2], round(best[1]["wall_s"] / best[2]["wall_s"], 2), \
        [round(a["wall_s"] / b["wall_s"], 2) for a, b in zip(runs[1], runs[2])]


def bench_throughput(records, workers, tmp):
    from cmsim.datasets import DatasetSpec, generate_dataset
    raw = tomllib.loads((ROOT / "datasets" / "gear_faults.toml").read_text())
    raw["dataset"]["records"] = records
    spec = DatasetSpec.from_dict(raw)
    out = Path(tmp) / f"tp{workers}"
    samples, stop = [], threading.Event()

    def watch():
        while not stop.is_set():
            samples.append(_rss_children(os.getpid()))
            time.sleep(0.5)

    th = threading.Thread(target=watch, daemon=True)
    th.start()
    s = generate_dataset(spec, out, workers=workers)
    stop.set()
    th.join()
    per_pid = {}
    for snap in samples:
        for pid, mb in snap.items():
            per_pid.setdefault(pid, []).append(mb)
    mem = {pid: (round(v[0], 1), round(max(v), 1), round(v[-1], 1))
           for pid, v in per_pid.items() if len(v) > 2}
    t = s.timing_s
    return {"workers": workers, "records": records, "wall_s": round(s.wall_s, 2),
            "records_per_hour": round(3600 * records / s.wall_s),
            "integration_share_of_busy": round(t["integration"] / t["busy"], 3),
            "integration_share_of_wall": round(t["integration"] / (s.wall_s * workers), 3),
            "setup_s": round(t["setup"], 2), "sensors_s": round(t["sensors"], 2),
            "save_s": round(t["save"], 2), "worker_rss_mb_first_max_last": mem}


def bench_resume_100k(tmp, n=100_000):
    import pandas as pd
    from cmsim.datasets import DatasetSpec
    from cmsim.datasets.manifest import RECORDS_DIR, ROWS_DIR, done_indices, open_directory
    raw = tomllib.loads((ROOT / "datasets" / "ci.toml").read_text())
    raw["dataset"]["records"] = n
    spec = DatasetSpec.from_dict(raw)
    out = Path(tmp) / "big"
    (out / RECORDS_DIR).mkdir(parents=True)
    (out / ROWS_DIR).mkdir()
    done = n - 10
    for i in range(done):
        (out / RECORDS_DIR / f"{i:06d}.npz").touch()
    cols = {"record_id": [f"{i:06d}" for i in range(done)], "index": range(done),
            "status": "ok", "error": None, "path": [f"records/{i:06d}.npz" for i in range(done)],
            "bytes": 0, "spec_digest": spec.digest, "fault_label": "healthy"}
    for k in range(60):                     # a realistic width
        cols[f"col{k}"] = 1.0
    pd.DataFrame(cols).to_parquet(out / "manifest.parquet", index=False)
    open_directory(spec, out, False)
    t = time.perf_counter()
    found, _ = done_indices(spec, out, verify=False)
    dt = time.perf_counter() - t
    assert len(found) == done
    return {"rows": done, "resume_scan_s": round(dt, 2),
            "manifest_mb": round((out / "manifest.parquet").stat().st_size / 1e6, 2)}


def bench_specs(tmp, sample):
    from cmsim.datasets import DatasetSpec, generate_dataset
    res = {}
    for path in sorted((ROOT / "datasets").glob("*.toml")):
        raw = tomllib.loads(path.read_text())
        total = DatasetSpec.from_dict(copy.deepcopy(raw), base_dir=path.parent).n_records
        raw["dataset"]["records"] = min(sample, total)
        spec = DatasetSpec.from_dict(raw, base_dir=path.parent)
        out = Path(tmp) / path.stem
        s = generate_dataset(spec, out, workers=2)
        size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())
        per = s.wall_s / spec.n_records
        res[path.stem] = {"records": total, "sampled": spec.n_records,
                          "s_per_record_2_workers": round(per, 3),
                          "est_total_min": round(per * total / 60, 1),
                          "bytes_per_record": int(size / spec.n_records),
                          "est_disk_mb": round(size / spec.n_records * total / 1e6, 1)}
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--records", type=int, default=16)
    ap.add_argument("--sample", type=int, default=8)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="bench_ds_")
    try:
        from cmsim.datasets import DatasetSpec, generate_dataset   # warm caches
        raw = tomllib.loads((ROOT / "datasets" / "gear_faults.toml").read_text())
        raw["dataset"]["records"] = 4
        generate_dataset(DatasetSpec.from_dict(raw), Path(tmp) / "warm", workers=2)
        one, two, speedup, each = bench_throughput_pairs(args.records, tmp)
        out = {"one_worker": one, "two_workers": two,
               "speedup_1_to_2": speedup, "speedup_each_pair": each,
               "resume_100k": bench_resume_100k(tmp),
               "standard_specs": bench_specs(tmp, args.sample),
               "load_average": os.getloadavg()}
        print(json.dumps(out, indent=1))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
