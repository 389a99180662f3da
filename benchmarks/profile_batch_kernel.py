"""Where a batched gear record's CPU goes, per numba function of the batch kernel (issue 49).

``perf`` sees numba's code as anonymous JIT memory. This script names it: the batch kernel's
cached object file (``integrate_batch_jit``'s ``.nbc``, an ELF object) lists every function
of the kernel with its offset; the run prints where the kernel's entry was loaded, so every
sample's address maps to the function it fell in (functions LLVM inlined count in their
caller)::

    perf record -F 2999 -o /tmp/batch.perf -- python benchmarks/profile_batch_kernel.py run
    python benchmarks/profile_batch_kernel.py report /tmp/batch.perf

``run`` simulates records of ``--spec`` (``datasets/gear_faults.toml``; ``--records`` of each kernel
layout, in batches of ``--batch``) in this process; ``report`` prints the share of all samples
per kernel function and per other library (libm, libpython, the kernel ...). Needs Linux
``perf`` and binutils' ``nm``.
"""

from __future__ import annotations

import argparse
import bisect
import collections
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ENTRY = "integrate_batch_jit"
#: What the run writes next to the perf data: where the kernel's entry was loaded.
ADDRESS_FILE = "kernel_address.json"


def _run(args):
    from cmsim.datasets.records import simulate_records
    from cmsim.datasets.runner import _batch_key
    from cmsim.datasets.spec import DatasetSpec
    from cmsim.dynamics._batch_kernels import integrate_batch_jit

    spec = DatasetSpec.load(args.spec)
    groups = {}
    for i in range(spec.n_records):
        plan = spec.record(i)
        groups.setdefault(_batch_key(plan), []).append(plan)
    for plans in groups.values():
        simulate_records(spec, plans[:args.records], batch_size=args.batch)
    cres = next(iter(integrate_batch_jit.overloads.values()))
    address = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
    Path(args.address).write_text(json.dumps({"address": address,
                                              "symbol": cres.fndesc.llvm_func_name}))
    print(f"{ENTRY} loaded at {address:#x} (written to {args.address})")


def _kernel_symbols(entry_symbol):
    """``[(offset, short name, symbol)]`` of the functions of the cached object file that
    holds ``entry_symbol`` (the loaded batch kernel), sorted: every ``.nbc`` of the kernel
    in the source tree's ``__pycache__`` and under ``NUMBA_CACHE_DIR`` is looked at."""
    roots = [ROOT / "cmsim" / "dynamics" / "__pycache__"]
    if os.environ.get("NUMBA_CACHE_DIR"):
        roots.append(Path(os.environ["NUMBA_CACHE_DIR"]))
    # the newest first: an older file of the kernel (another line number, the same
    # symbols) is left behind when its source moves, and its offsets are not the loaded ones
    cached = sorted((p for root in roots for p in root.rglob(f"_batch_kernels.{ENTRY}-*.nbc")),
                    key=lambda p: p.stat().st_mtime, reverse=True)
    for path in cached:
        data = path.read_bytes()
        with tempfile.NamedTemporaryFile(suffix=".o") as obj:
            obj.write(data[data.find(b"\x7fELF"):])
            obj.flush()
            out = subprocess.run(["nm", "--defined-only", obj.name], capture_output=True,
                                 text=True, check=True).stdout
        symbols = []
        for line in out.splitlines():
            parts = line.split()
            if len(parts) == 3 and parts[1] in "TtWw":
                m = re.search(r"\d(_[a-z_]+_kernels)\d+([A-Za-z_]+?)B\d", parts[2])
                symbols.append((int(parts[0], 16), f"{m.group(1)}.{m.group(2)}" if m else
                                parts[2][:60], parts[2]))
        if any(full == entry_symbol for _, _, full in symbols):
            return sorted(symbols)
    sys.exit(f"no cached batch kernel holds {entry_symbol[:60]}...: run "
             f"`... profile_batch_kernel.py run` again")


def _report(args):
    loaded = json.loads(Path(args.address).read_text())
    symbols = _kernel_symbols(loaded["symbol"])
    entry = next(off for off, _, full in symbols if full == loaded["symbol"])
    offsets = [s[0] for s in symbols]
    script = subprocess.run(["perf", "script", "-i", args.data, "-F", "ip,dso"],
                            capture_output=True, text=True, check=True).stdout
    counts, total = collections.Counter(), 0
    for line in script.splitlines():
        parts = line.split()
        if not parts:
            continue
        total += 1
        ip, dso = int(parts[0], 16), parts[-1]
        offset = ip - loaded["address"] + entry
        if "perf-" in dso and 0 <= offset < offsets[-1] + 0x10000:
            counts[symbols[bisect.bisect_right(offsets, offset) - 1][1]] += 1
        elif "perf-" in dso:
            counts["(other) numba code outside the batch kernel (housing path, filters)"] += 1
        else:
            counts[f"(other) {Path(dso.strip('()')).name}"] += 1
    print(f"{total} samples")
    for name, n in counts.most_common(args.top):
        print(f"{100.0 * n / total:6.2f} %  {name}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="step", required=True)
    run = sub.add_parser("run")
    run.add_argument("--records", type=int, default=124,
                     help="records of each kernel layout (fault kinds that share a batch)")
    run.add_argument("--batch", type=int, default=128)
    run.add_argument("--spec", type=Path, default=ROOT / "datasets" / "gear_faults.toml",
                     help="the dataset spec whose records are run (default: gear_faults)")
    run.add_argument("--address", default=f"/tmp/{ADDRESS_FILE}")
    report = sub.add_parser("report")
    report.add_argument("data", help="perf.data of the run")
    report.add_argument("--address", default=f"/tmp/{ADDRESS_FILE}")
    report.add_argument("--top", type=int, default=40)
    args = parser.parse_args()
    (_run if args.step == "run" else _report)(args)


if __name__ == "__main__":
    main()
