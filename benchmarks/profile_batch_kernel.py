"""Where a batched gear record's CPU goes, per numba function of the batch kernel (issue 49).

``perf`` sees numba's code as anonymous JIT memory. This script names it: the batch kernel's
cached object file (``integrate_batch_jit``'s ``.nbc``, an ELF object) lists every function
of the kernel with its offset; the run prints where the kernel's entry was loaded, so every
sample's address maps to the function it fell in (functions LLVM inlined count in their
caller)::

    perf record -F 2999 -o /tmp/batch.perf -- python benchmarks/profile_batch_kernel.py run
    python benchmarks/profile_batch_kernel.py report /tmp/batch.perf

``run`` simulates records of ``datasets/gear_faults.toml`` (``--records`` of each fault
kind, in batches of ``--batch``) in this process; ``report`` prints the share of all samples
per kernel function and per other library (libm, libpython, the kernel ...). Needs Linux
``perf`` and binutils' ``nm``.
"""

from __future__ import annotations

import argparse
import bisect
import collections
import glob
import json
import re
import subprocess
import sys
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

    spec = DatasetSpec.load(ROOT / "datasets" / "gear_faults.toml")
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


def _kernel_symbols():
    """``[(offset, short name)]`` of the cached batch kernel's functions, sorted."""
    cached = sorted(glob.glob(str(ROOT / "cmsim" / "dynamics" / "__pycache__" /
                                  f"_batch_kernels.{ENTRY}-*.nbc")))
    if not cached:
        sys.exit("no cached batch kernel: run `... profile_batch_kernel.py run` first")
    data = Path(cached[-1]).read_bytes()
    obj = Path("/tmp") / "cmsim_batch_kernel.o"
    obj.write_bytes(data[data.find(b"\x7fELF"):])
    out = subprocess.run(["nm", "--defined-only", str(obj)], capture_output=True, text=True,
                         check=True).stdout
    symbols = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1] in "TtWw":
            m = re.search(r"\d(_[a-z_]+_kernels)\d+([A-Za-z_]+?)B\d", parts[2])
            symbols.append((int(parts[0], 16), f"{m.group(1)}.{m.group(2)}" if m else
                            parts[2][:60], parts[2]))
    return sorted(symbols)


def _report(args):
    loaded = json.loads(Path(args.address).read_text())
    symbols = _kernel_symbols()
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
    run.add_argument("--records", type=int, default=124, help="records of each fault kind")
    run.add_argument("--batch", type=int, default=128)
    run.add_argument("--address", default=f"/tmp/{ADDRESS_FILE}")
    report = sub.add_parser("report")
    report.add_argument("data", help="perf.data of the run")
    report.add_argument("--address", default=f"/tmp/{ADDRESS_FILE}")
    report.add_argument("--top", type=int, default=40)
    args = parser.parse_args()
    (_run if args.step == "run" else _report)(args)


if __name__ == "__main__":
    main()
