"""Hand-made mutants ("planted bugs") run against the tests meant to catch them.

Each mutant is a one-line change a developer could plausibly make. The script copies the
package (``cmsim/``, ``tests/``, ``pyproject.toml``) to a scratch directory, applies one
mutant at a time, and runs the named test files there with pytest; a mutant is *killed* when
pytest fails. Nothing in the checkout is modified.

numba does not recompile a caller when a function it inlined from another file changes, so
a mutant in a ``_kernels.py`` file runs with a fresh, empty ``NUMBA_CACHE_DIR``; mutants in
pure-Python files share one cache (their kernels are unchanged).

Usage (from the repository root; about 1 min per kernel mutant, seconds otherwise)::

    .venv/bin/python benchmarks/mutation/planted.py            # all mutants
    .venv/bin/python benchmarks/mutation/planted.py -k rollers # ids containing "rollers"
    .venv/bin/python benchmarks/mutation/planted.py --rev HEAD # a committed tree instead
    .venv/bin/python benchmarks/mutation/planted.py --rev HEAD --overlay tests/test_x.py
    .venv/bin/python benchmarks/mutation/planted.py --list

Exit status 0 when every mutant is killed and the unmutated copy passes.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Mutant:
    """One planted bug: replace ``old`` (exactly once) by ``new`` in ``path``."""

    id: str
    gap: str
    path: str
    old: str
    new: str
    tests: tuple


MUTANTS = (
    # --- only symmetric cases tested (issue 14): Z1/Z2, r_b1/r_b2, shaft speeds
    Mutant("asym-speed-ratio", "symmetric", "cmsim/dynamics/model.py",
           "ratio = rig.gears.driving.n_teeth / rig.gears.driven.n_teeth if rig.gears",
           "ratio = rig.gears.driven.n_teeth / rig.gears.driving.n_teeth if rig.gears",
           ("tests/unit/dynamics/test_asymmetric_pair.py",)),
    Mutant("asym-dte-ratio", "symmetric", "cmsim/dynamics/simulation.py",
           "ratio = rig.gears.driven.n_teeth / rig.gears.driving.n_teeth",
           "ratio = rig.gears.driving.n_teeth / rig.gears.driven.n_teeth",
           ("tests/unit/dynamics/test_asymmetric_pair.py",)),
    Mutant("asym-fr2", "symmetric", "cmsim/frequencies.py",
           "f2 = f1 * z1 / z2", "f2 = f1 * z2 / z1",
           ("tests/unit/dynamics/test_asymmetric_pair.py",)),
    Mutant("asym-dte-um-radius", "symmetric", "cmsim/dynamics/simulation.py",
           'sig["dte_um"] = dte * rig.gears.driving.base_radius_m * 1e6',
           'sig["dte_um"] = dte * rig.gears.driven.base_radius_m * 1e6',
           ("tests/unit/dynamics/test_asymmetric_pair.py",)),
    Mutant("asym-kernel-rb", "symmetric", "cmsim/dynamics/_mesh_kernels.py",
           "delta_inv = (rb1 * (y[i1 + 2] + mp[MP_PSI10] - phi_t1)",
           "delta_inv = (rb2 * (y[i1 + 2] + mp[MP_PSI10] - phi_t1)",
           ("tests/unit/dynamics/test_asymmetric_pair.py", "tests/unit/mesh_stiffness/test_table_separation.py")),
    # --- documented options without a test of their own physics
    Mutant("rollers-force-exponent", "rollers", "cmsim/bearings/_kernels.py",
           "f = d ** p", "f = d * math.sqrt(d)", ("tests/unit/bearings/test_rollers.py",)),
    Mutant("rollers-tangent", "rollers", "cmsim/bearings/_kernels.py",
           "g = k * p * d ** (p - 1.0)", "g = k * 1.5 * math.sqrt(d)",
           ("tests/unit/bearings/test_rollers.py",)),
    Mutant("rollers-model-exponent", "rollers", "cmsim/dynamics/rig_model.py",
           "b_par[ib, K.BP_P] = brg.load_exponent", "b_par[ib, K.BP_P] = 1.5",
           ("tests/unit/bearings/test_rollers.py",)),
    Mutant("table-separation-ignored", "separation", "cmsim/dynamics/_mesh_kernels.py",
           "overlap = delta - e_pair", "overlap = delta",
           ("tests/unit/mesh_stiffness/test_table_separation.py",)),
    Mutant("table-separation-sign", "separation", "cmsim/dynamics/_mesh_kernels.py",
           "overlap = delta - e_pair", "overlap = delta + e_pair",
           ("tests/unit/mesh_stiffness/test_table_separation.py",)),
    # --- boundaries: envelope band edges
    Mutant("envelope-nyquist-branch", "boundaries", "cmsim/spectra/envelope.py",
           "elif hi >= nyq:", "elif hi > nyq:", ("tests/unit/spectra/test_envelope_edges.py",)),
    Mutant("envelope-highpass-type", "boundaries", "cmsim/spectra/envelope.py",
           'sos = scipy.signal.butter(order, lo, btype="highpass"',
           'sos = scipy.signal.butter(order, lo, btype="lowpass"',
           ("tests/unit/spectra/test_envelope_edges.py",)),
    Mutant("envelope-lowpass-edge", "boundaries", "cmsim/spectra/envelope.py",
           'sos = scipy.signal.butter(order, hi, btype="lowpass"',
           'sos = scipy.signal.butter(order, hi, btype="highpass"',
           ("tests/unit/spectra/test_envelope_edges.py",)),
    # --- CLI options that must reach the run
    Mutant("cli-warmup-dropped", "cli", "cmsim/cli.py",
           "seed=args.seed, warmup_s=args.warmup_s)", "seed=args.seed)",
           ("tests/cli/test_options_reach_meta.py",)),
    Mutant("cli-friction-dropped", "cli", "cmsim/cli.py",
           "rig = rig.with_friction(args.friction)", "rig = rig.with_friction(0.0)",
           ("tests/cli/test_options_reach_meta.py",)),
    Mutant("cli-correlation-default", "cli", "cmsim/cli.py",
           "correlation_s=args.slip_correlation_s)", "correlation_s=5e-3)",
           ("tests/cli/test_options_reach_meta.py",)),
    # --- caches and resume
    Mutant("cache-key-bore", "caches", "cmsim/mesh_stiffness/influence.py",
           '"tip_radius_coef", "bore_radius_m", "youngs_modulus_pa"',
           '"tip_radius_coef", "youngs_modulus_pa"', ("tests/unit/mesh_stiffness/test_cache_keys.py",)),
    Mutant("resume-seed-unchecked", "caches", "cmsim/datasets/manifest.py",
           'if row.get("spec_digest") != spec.digest or f"{row[\'record_id\']}.npz" != path.name:',
           'if f"{row[\'record_id\']}.npz" != path.name:', ("tests/unit/mesh_stiffness/test_cache_keys.py",)),
    # --- time bases
    Mutant("time-off-by-one", "time", "cmsim/dynamics/simulation.py",
           "t = (n_warm + np.arange(n_rec)) * dt", "t = (n_warm + 1 + np.arange(n_rec)) * dt",
           ("tests/unit/dynamics/test_time_base.py",)),
    Mutant("time-warmup-samples", "time", "cmsim/dynamics/simulation.py",
           "n_warm = int(round(warmup_s * fs_hz))\n        report",
           "n_warm = int(warmup_s * fs_hz) + 1\n        report",
           ("tests/unit/dynamics/test_time_base.py",)),
    # --- scheme data
    Mutant("tableau-ode3-node", "schemes", "cmsim/dynamics/integrator.py",
           "np.array([0.0, 0.5, 0.75]), 3)", "np.array([0.0, 0.5, 0.5]), 3)",
           ("tests/unit/dynamics/test_tableaus.py",)),
    Mutant("tableau-rk4-weight", "schemes", "cmsim/dynamics/integrator.py",
           "np.array([1.0, 2.0, 2.0, 1.0]) / 6.0", "np.array([1.0, 2.5, 1.5, 1.0]) / 6.0",
           ("tests/unit/dynamics/test_tableaus.py",)),
    # --- tests that asserted little (strengthened)
    Mutant("cage-model-outer-sign", "weak", "cmsim/dynamics/rig_model.py",
           "b_par[ib, K.BP_CAGE] = k_in + k_out * brg.outer_ring_speed_ratio",
           "b_par[ib, K.BP_CAGE] = k_in - k_out * brg.outer_ring_speed_ratio",
           ("tests/unit/bearings/test_bearings.py",)),
    Mutant("cage-angle-outer-ratio", "weak", "cmsim/bearings/kinematics.py",
           "k_in * np.asarray(theta_inner_rad) + k_out * np.asarray(theta_outer_rad)",
           "k_in * np.asarray(theta_inner_rad) + k_in * np.asarray(theta_outer_rad)",
           ("tests/unit/bearings/test_bearings.py",)),
    Mutant("modes-rotor-inertia", "weak", "cmsim/dynamics/model.py",
           "centre = (shaft.rotor.mass_kg, shaft.rotor.inertia_kg_m2)",
           "centre = (shaft.rotor.mass_kg, shaft.bearing_1.inertia_kg_m2)",
           ("tests/literature/test_modes.py::test_bearing_rig_modes",)),
    Mutant("kurtogram-map-offset", "weak", "cmsim/spectra/plots.py",
           "idx = np.clip(np.searchsorted(edges, grid) - 1, 0, sk.size - 1)",
           "idx = np.clip(np.searchsorted(edges, grid), 0, sk.size - 1)",
           ("tests/unit/spectra/test_plots.py::test_plot_kurtogram",)),
    Mutant("features-dominant-reversed", "weak", "cmsim/features.py",
           "return int(np.nanargmax(a)) + 1", "return int(np.nanargmax(a[::-1])) + 1",
           ("tests/unit/datasets/test_sweep.py::test_sweep_writes_runs_and_manifest",)),
    Mutant("cli-friction-in-simulate", "weak", "cmsim/cli.py",
           "rig = rig.with_friction(args.friction)", "rig = rig",
           ("tests/cli/test_commands.py::test_simulate_with_options",)),
    Mutant("doc-param-renamed", "weak", "cmsim/spectra/envelope.py",
           "    filter_order : int\n        Butterworth order per edge",
           "    order : int\n        Butterworth order per edge",
           ("tests/structure/test_docstrings.py",)),
)


def _copy_tree(dst, rev, overlay=()):
    if dst.exists():
        shutil.rmtree(dst)
    dst.mkdir(parents=True)
    if rev:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "cmsim", "tests",
                                  "pyproject.toml"], check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(dst)], input=archive, check=True)
        for rel in overlay:                    # working-tree files over the revision
            shutil.copy2(ROOT / rel, dst / rel)
        return
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".pytest_cache")
    for name in ("cmsim", "tests"):
        shutil.copytree(ROOT / name, dst / name, ignore=ignore)
    shutil.copy2(ROOT / "pyproject.toml", dst / "pyproject.toml")


def _pytest(work, tests, cache_dir, timeout_s):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir), MPLBACKEND="Agg",
               PYTHONPATH=str(work), PYTHONDONTWRITEBYTECODE="1")
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests]
    start = time.perf_counter()
    try:
        proc = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True,
                              timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - start, ""
    tail = [ln for ln in proc.stdout.splitlines() if ln.startswith(("FAILED", "ERROR"))]
    return proc.returncode, time.perf_counter() - start, tail[0] if tail else ""


def main(argv=None):
    """Run the planted mutants; print one line per mutant and a summary."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("-k", default="", help="run mutants whose id or gap contains this")
    p.add_argument("--rev", help="git revision to copy instead of the working tree")
    p.add_argument("--overlay", nargs="*", default=(), metavar="FILE",
                   help="with --rev: take these files from the working tree")
    p.add_argument("--work", type=Path, default=Path(tempfile.gettempdir()) / "cmsim-planted")
    p.add_argument("--timeout-s", type=float, default=900.0)
    p.add_argument("--list", action="store_true")
    args = p.parse_args(argv)
    chosen = [m for m in MUTANTS if args.k in m.id or args.k in m.gap]
    if args.list:
        for m in chosen:
            print(f"{m.id:28s} {m.path}: {m.old.strip()!r} -> {m.new.strip()!r}")
        return 0
    pkg = args.work / "pkg"
    shared_cache = args.work / "numba-shared"
    _copy_tree(pkg, args.rev, args.overlay)
    tests = sorted({t for m in chosen for t in m.tests})
    status, secs, why = _pytest(pkg, tests, shared_cache, args.timeout_s)
    print(f"{'baseline':28s} {'pass' if status == 0 else 'FAIL'} {secs:6.1f} s {why}",
          flush=True)
    if status != 0:
        return 2
    survived = []
    for m in chosen:
        _copy_tree(pkg, args.rev, args.overlay)
        target = pkg / m.path
        text = target.read_text()
        if text.count(m.old) != 1:
            print(f"{m.id:28s} STALE (the line to mutate is not found once in {m.path})")
            survived.append(m.id)
            continue
        target.write_text(text.replace(m.old, m.new))
        fresh = m.path.endswith("_kernels.py")
        cache = args.work / f"numba-{m.id}" if fresh else shared_cache
        status, secs, why = _pytest(pkg, list(m.tests), cache, args.timeout_s)
        if fresh:
            shutil.rmtree(cache, ignore_errors=True)
        killed = status != 0
        if not killed:
            survived.append(m.id)
        print(f"{m.id:28s} {'killed' if killed else 'SURVIVED'} {secs:6.1f} s {why}",
              flush=True)
    print(f"{len(chosen) - len(survived)}/{len(chosen)} planted mutants killed"
          + (f"; survived: {', '.join(survived)}" if survived else ""))
    return 0 if not survived else 1


if __name__ == "__main__":
    sys.exit(main())
