"""mutmut on the pure-Python modules, in a scratch copy of the package.

mutmut 2 mutates files in place, so the package (``cmsim/``, ``tests/``) is copied to a
scratch directory first (``--rev`` copies a committed tree instead of the working tree) and
mutmut runs there; the checkout is never touched. The runner is pytest on the fast test files
that cover these modules (a few seconds per mutant), stopped at the first failure.

Usage (from the repository root; needs ``pip install -e .[mutation]``)::

    .venv/bin/python benchmarks/mutation/run_mutmut.py                 # all modules below
    .venv/bin/python benchmarks/mutation/run_mutmut.py cmsim/frequencies.py
    .venv/bin/python benchmarks/mutation/run_mutmut.py --rev HEAD --overlay tests/test_x.py

then, once it has finished, ``cd /tmp/cmsim-mutmut/pkg && mutmut results`` / ``mutmut show
<id>`` to read the survivors. The score is killed / (total − equivalent); the mutants judged equivalent are
listed in ``benchmarks/mutation/README.md``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from planted import _copy_tree  # noqa: E402

#: Modules mutated by default: small, pure Python, with closed-form tests (238 mutants, about
#: 30 min on one core). cmsim/bearings/hertz.py (128) and cmsim/mesh_stiffness/table.py (115)
#: are the next candidates: pass them as arguments.
MODULES = ("cmsim/frequencies.py", "cmsim/bearings/kinematics.py", "cmsim/spectra/envelope.py")

#: Fast test files that exercise those modules, quickest killers first (pytest stops at the
#: first failure); the dynamics tests are left out to keep a mutant at a few seconds.
TESTS = ("tests/unit/frequencies/test_contract.py", "tests/unit/bearings/test_kinematics_envelope_contract.py",
         "tests/unit/frequencies/test_frequencies.py", "tests/unit/bearings/test_bearings.py", "tests/unit/spectra/test_envelope_edges.py",
         "tests/unit/spectra/test_envelope.py", "tests/unit/bearings/test_rollers.py")


def main(argv=None):
    """Copy the package, run mutmut on ``modules`` and print ``mutmut results``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("modules", nargs="*", default=MODULES)
    p.add_argument("--rev", help="git revision to copy instead of the working tree")
    p.add_argument("--overlay", nargs="*", default=(), metavar="FILE",
                   help="with --rev: take these files from the working tree")
    p.add_argument("--work", type=Path, default=Path(tempfile.gettempdir()) / "cmsim-mutmut")
    args = p.parse_args(argv)
    pkg = args.work / "pkg"
    _copy_tree(pkg, args.rev, args.overlay)
    tests = [t for t in TESTS if (pkg / t).is_file()]
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(pkg),
               NUMBA_CACHE_DIR=str(args.work / "numba"))
    runner = f"{sys.executable} -m pytest -x -q -p no:cacheprovider " + " ".join(tests)
    mutmut = shutil.which("mutmut", path=str(Path(sys.executable).parent)) or "mutmut"
    cmd = [mutmut, "run", "--paths-to-mutate", ",".join(args.modules), "--tests-dir", "tests",
           "--runner", runner, "--no-progress"]
    subprocess.run(cmd, cwd=pkg, env=env)
    res = subprocess.run([mutmut, "results"], cwd=pkg, env=env, capture_output=True, text=True)
    print(res.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
