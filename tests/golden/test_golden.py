"""Golden regression: a same-code regression guard, not physical validation.

Tier (c) golden JSON. Short dynamic runs of the paper rig and of a bearing rig are reduced to
robust scalar summaries and compared with ``tests/golden/dynamics_golden.json``, which was
written by this module from the code as it stood before the numba kernels were reorganised.
A change of those numbers means the simulation changed; whether the new numbers are *right*
is for the literature and closed-form tiers to say.

Regenerate (from the repository root) with::

    .venv/bin/python -m tests.golden.test_golden --regenerate
    # or: .venv/bin/python tests/golden/test_golden.py --regenerate

then review the diff of the JSON file before committing it.

Cases (each described as data in :data:`CASES`, one :func:`_run_case` builds the call; seed
and cage phases fixed): the paper rig at 1000 rpm with (a) an explicit potential-energy mesh
table, 100 N·m; (b) the on-line hybrid contact solve (paper 001 §6.1 model A), 100 N·m,
shorter; (c) preload, clearance -1e-6 m, 10 N·m; (d) mesh friction 0.05, 10 N·m; (e) a rotor
on two 209 bearings with a 1 kN radial load.

Stored per case: mean, RMS and standard deviation of ``dte_um`` and of each bearing's LOA
force ``F_<b>_loa``; the amplitudes of harmonics 1-5 of the GMF (of the 1b1 ball-pass
frequency for the bearing rig) in ``F_1b1_loa`` and ``dte_um`` (flat-top amplitude
spectrum); a 50-sample decimated excerpt of the ``dte_um`` (``F_1b1_loa``) waveform.

Tolerance. Each stored number is compared with an absolute tolerance ``RTOL * scale`` where
the scale is the quantity's own size: ``|x|`` for means and RMS, the standard deviation for
the standard deviation and for the waveform samples, the largest of the five harmonics for
each harmonic. Measured on the five cases at commit 3d95ac0 (``--measure``/``--compare``;
largest normalised deviation over all numbers of a case):

* reproducibility: rerun in the same process and in a new process, bit-identical (0);
* floating-point drift between machines, three proxies: kernels compiled for a generic
  x86-64 CPU (``NUMBA_CPU_NAME=generic``: no AVX/FMA, other vectorisation of the fastmath
  ball loop), without LLVM optimisation (``NUMBA_OPT=0``) or both: at most 2.9e-11; the
  output inertia (rotor mass) perturbed by 1e-12 relative: at most 5.9e-11 (the runs do not
  amplify round-off: a 1e-12 change stays below 1e-10);
* step convergence, ``substeps=2`` (half the integration step), largest change per case
  2.9e-3 (rotor rig) to 1.9e-2 (friction); per group of numbers, over the four gear-rig
  cases: means/RMS 3.2e-5 to 4.5e-5, standard deviations 1.0e-3 to 5.1e-3, GMF harmonics
  2.5e-4 to 6.8e-3, waveform 7.1e-3 to 1.9e-2 (the rotor rig's means and harmonics barely
  depend on the step: 8e-9 and 6e-6; its standard deviations and waveform move 1.4e-3 and
  2.9e-3).

``RTOL = 1e-5`` is 1.7e5 times the largest drift seen (room for numba/LLVM/libm/scipy
versions and the FE solve of the hybrid case) and 290 times below the smallest per-case
half-step change, so halving the step fails every case; for the gear rigs it is also below
the half-step change of every group (means 3x, harmonics 25x, standard deviations 100x,
waveform 700x). A tolerance of 1e-3 would have let a halved step through in all means and
in the harmonics of the 10 N·m cases.
"""

from __future__ import annotations

import argparse
import copy
import inspect
import json
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

GOLDEN_PATH = Path(__file__).resolve().parent / "dynamics_golden.json"

#: Relative tolerance on every stored number, relative to the quantity's own scale (see the
#: module docstring for the measurements behind it).
RTOL = 1e-5

#: Harmonics stored per signal and samples in the waveform excerpt.
N_HARMONICS = 5
N_EXCERPT = 50

_CAGES_GEAR_RIG = [0.3, 1.7, 2.9, 4.4]      # rad, bearings 1b1, 1b2, 2b1, 2b2
_CAGES_ROTOR_RIG = [0.3, 1.7]               # rad, bearings 1b1, 1b2

_COMMON = {"speed_rpm": 1000.0, "fs_hz": 75_000.0, "warmup_s": 0.05, "seed": 1,
           "substeps": 1}

#: The golden cases as data: rig (name and variant), operating point, options, mesh kind.
#: ``mesh``: ``"pe-table"`` (an explicit potential-energy MeshStiffnessTable object),
#: ``"hybrid"`` (a HybridMeshModel object, on-line contact) or ``None`` (no gears).
CASES = {
    "paper_pe_table_100nm": {
        "rig": "paper_2016", "rig_variant": {}, **_COMMON, "torque_nm": 100.0,
        "radial_load_n": 0.0, "duration_s": 0.3, "mesh": "pe-table",
        "cage_phases_rad": _CAGES_GEAR_RIG},
    "paper_hybrid_100nm": {
        "rig": "paper_2016", "rig_variant": {}, **_COMMON, "torque_nm": 100.0,
        "radial_load_n": 0.0, "duration_s": 0.12, "mesh": "hybrid",
        "cage_phases_rad": _CAGES_GEAR_RIG},
    "paper_preload_10nm": {
        "rig": "paper_2016", "rig_variant": {"clearance_m": -1e-6}, **_COMMON,
        "torque_nm": 10.0, "radial_load_n": 0.0, "duration_s": 0.3, "mesh": "pe-table",
        "cage_phases_rad": _CAGES_GEAR_RIG},
    "paper_friction_0.05_10nm": {
        "rig": "paper_2016", "rig_variant": {"friction_coefficient": 0.05}, **_COMMON,
        "torque_nm": 10.0, "radial_load_n": 0.0, "duration_s": 0.3, "mesh": "pe-table",
        "cage_phases_rad": _CAGES_GEAR_RIG},
    "rotor_on_209_bearings_1kn": {
        "rig": "rotor_on_bearings", "rig_variant": {"rotor_mass_kg": 4.0,
                                                    "rotor_inertia_kg_m2": 0.01},
        **_COMMON, "torque_nm": 0.0, "radial_load_n": 1000.0, "duration_s": 0.3,
        "mesh": None, "cage_phases_rad": _CAGES_ROTOR_RIG},
}


# ---------------------------------------------------------------------------- building runs
def _build_rig(case, perturb=0.0):
    """The case's rig; ``perturb`` scales one inertia by (1 + perturb) (round-off proxy)."""
    from cmsim.rig import Rig, Rotor
    variant = dict(case["rig_variant"])
    if case["rig"] == "paper_2016":
        rig = Rig.paper_2016()
        if "clearance_m" in variant:
            rig = rig.with_clearance(variant.pop("clearance_m"))
        if "friction_coefficient" in variant:
            rig = rig.with_friction(variant.pop("friction_coefficient"))
        if perturb:
            rig = replace(rig, output_inertia_kg_m2=rig.output_inertia_kg_m2 * (1 + perturb))
    elif case["rig"] == "rotor_on_bearings":
        bearing = Rig.paper_2016().bearings[0]
        rotor = Rotor(mass_kg=variant.pop("rotor_mass_kg") * (1 + perturb),
                      inertia_kg_m2=variant.pop("rotor_inertia_kg_m2"))
        rig = Rig.rotor_on_bearings(bearing, rotor)
    else:
        raise ValueError(f"unknown rig {case['rig']!r}")
    if variant:
        raise ValueError(f"unused rig_variant keys {sorted(variant)}")
    return rig


_HYBRID = {}


def _hybrid_model(pair):
    if pair not in _HYBRID:
        from cmsim.mesh_stiffness.hybrid import HybridMeshModel
        _HYBRID[pair] = HybridMeshModel.from_pair(pair)
    return _HYBRID[pair]


def _run_case(case, *, substeps=None, perturb=0.0):
    """Simulate one case; works with ``simulate(mesh=...)`` and the older keywords.

    Parameters
    ----------
    case : dict
        An entry of :data:`CASES`.
    substeps : int, optional
        Override of ``case["substeps"]`` (step-convergence measurement).
    perturb : float
        Relative change of one inertia (round-off proxy; 0 for the golden values).

    Returns
    -------
    Run
    """
    from cmsim.dynamics.simulation import simulate
    from cmsim.rig import OperatingPoint
    rig = _build_rig(case, perturb)
    op = OperatingPoint(case["speed_rpm"], case["torque_nm"],
                        radial_load_n=case["radial_load_n"])
    kw = dict(fs_hz=case["fs_hz"], warmup_s=case["warmup_s"], seed=case["seed"],
              substeps=case["substeps"] if substeps is None else substeps,
              cage_phases_rad=list(case["cage_phases_rad"]))
    mesh_kind = case["mesh"]
    if mesh_kind is None:
        mesh = None
    elif mesh_kind == "pe-table":
        from cmsim.mesh_stiffness.table import MeshStiffnessTable
        mesh = MeshStiffnessTable.potential_energy(rig.gears)
    elif mesh_kind == "hybrid":
        mesh = _hybrid_model(rig.gears)
    else:
        raise ValueError(f"unknown mesh kind {mesh_kind!r}")
    params = inspect.signature(simulate).parameters
    if mesh is not None:
        if "mesh" in params:
            kw["mesh"] = mesh
        elif mesh_kind == "hybrid":
            kw["mesh_model"] = mesh
        else:
            kw["mesh_table"] = mesh
    return simulate(rig, op, case["duration_s"], **kw)


# ---------------------------------------------------------------------------- summaries
def _stats(x):
    x = np.asarray(x, dtype=float)
    return {"mean": float(x.mean()), "rms": float(np.sqrt(np.mean(x * x))),
            "std": float(x.std())}


def _harmonics(x, fs_hz, base_hz):
    from cmsim.spectra.amplitude import amplitude_spectrum
    from cmsim.spectra.waterfall import harmonic_amplitudes
    spec = amplitude_spectrum(np.asarray(x, dtype=float), fs_hz)
    return [float(a) for a in harmonic_amplitudes(spec.freq_hz, spec.amplitude, base_hz,
                                                  N_HARMONICS)]


def summarise(run, case):
    """Scalar summaries of a run (the ``outputs`` of a golden case)."""
    from cmsim.rig import OperatingPoint
    from cmsim.spectra.frequencies import rig_frequencies
    rig = _build_rig(case)
    freqs = rig_frequencies(rig, OperatingPoint(case["speed_rpm"], case["torque_nm"]))
    if rig.has_gears:
        base_name, base_hz, wave = "gmf_hz", freqs["gmf_hz"], "dte_um"
        harm_signals = ("F_1b1_loa", "dte_um")
    else:
        base_name, base_hz, wave = "bpf_1b1_hz", freqs["1b1"]["bpf_hz"], "F_1b1_loa"
        harm_signals = ("F_1b1_loa",)
    stat_signals = ((("dte_um",) if rig.has_gears else ())
                    + tuple(f"F_{b}_loa" for b in rig.bearing_names))
    idx = np.round(np.linspace(0, run.t.size - 1, N_EXCERPT)).astype(int)
    return {
        "stats": {name: _stats(run[name]) for name in stat_signals},
        "harmonics": {"base": base_name, "base_hz": float(base_hz),
                      **{name: _harmonics(run[name], run.fs_hz, base_hz)
                         for name in harm_signals}},
        "excerpt": {"signal": wave, "t_s": [float(v) for v in run.t[idx]],
                    "values": [float(v) for v in run[wave][idx]],
                    "std": float(np.std(run[wave]))},
    }


def deviations(ref, new):
    """Normalised deviations ``|new - ref| / scale`` of every stored number.

    Returns
    -------
    dict of str to float
        Keyed ``"<group>/<signal>/<quantity>"``; the scale is described in the module
        docstring.
    """
    out = {}
    for name, s in ref["stats"].items():
        n = new["stats"][name]
        for q in ("mean", "rms"):
            out[f"stats/{name}/{q}"] = abs(n[q] - s[q]) / max(abs(s[q]), 1e-300)
        out[f"stats/{name}/std"] = abs(n["std"] - s["std"]) / max(s["std"], 1e-300)
    for name, h in ref["harmonics"].items():
        if name in ("base", "base_hz"):
            continue
        scale = max(max(h), 1e-300)
        hn = new["harmonics"][name]
        for k, (a, b) in enumerate(zip(h, hn), start=1):
            out[f"harmonics/{name}/{k}"] = abs(b - a) / scale
    e, en = ref["excerpt"], new["excerpt"]
    wave = np.abs(np.asarray(en["values"]) - np.asarray(e["values"])) / max(e["std"], 1e-300)
    out[f"excerpt/{e['signal']}/max"] = float(wave.max())
    return out


# ---------------------------------------------------------------------------- the tests
@pytest.fixture(scope="module")
def golden():
    if not GOLDEN_PATH.exists():
        pytest.fail(f"{GOLDEN_PATH} missing; regenerate with "
                    f"`python -m tests.golden.test_golden --regenerate`")
    return json.loads(GOLDEN_PATH.read_text())


def test_golden_cases_match_their_inputs(golden):
    """The stored inputs are the cases run here (no silent drift of the case definitions)."""
    assert set(golden["cases"]) == set(CASES)
    for name, case in CASES.items():
        assert golden["cases"][name]["inputs"] == json.loads(json.dumps(case)), name


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES))
def test_golden_case(golden, name):
    case = CASES[name]
    ref = golden["cases"][name]["outputs"]
    new = summarise(_run_case(case), case)
    assert set(new["stats"]) == set(ref["stats"])
    assert new["harmonics"]["base_hz"] == pytest.approx(ref["harmonics"]["base_hz"], rel=1e-12)
    dev = deviations(ref, new)
    bad = {k: v for k, v in dev.items() if not v <= RTOL}
    assert not bad, (f"{name}: {len(bad)} of {len(dev)} numbers moved by more than "
                     f"RTOL = {RTOL:g} of their scale: "
                     + ", ".join(f"{k} {v:.2e}" for k, v in sorted(bad.items())[:12]))


def test_deviation_measure_detects_a_change():
    """The comparison itself: a 1 % change of one harmonic is reported, none is not."""
    ref = {"stats": {"dte_um": {"mean": 5.0, "rms": 5.1, "std": 0.2}},
           "harmonics": {"base": "gmf_hz", "base_hz": 466.7, "dte_um": [0.1, 0.02, 0.01]},
           "excerpt": {"signal": "dte_um", "t_s": [0.0, 1.0], "values": [4.9, 5.2],
                       "std": 0.2}}
    assert max(deviations(ref, ref).values()) < 1e-15
    new = copy.deepcopy(ref)
    new["harmonics"]["dte_um"][2] *= 1.01
    dev = deviations(ref, new)
    assert dev["harmonics/dte_um/3"] == pytest.approx(1e-3, rel=1e-9)   # 1e-4 / 0.1
    new["excerpt"]["values"][1] += 0.01
    assert deviations(ref, new)["excerpt/dte_um/max"] == pytest.approx(0.05, rel=1e-9)


# ---------------------------------------------------------------------------- generation
def regenerate(path=GOLDEN_PATH):
    """Run every case and write the golden JSON (inputs and outputs per case)."""
    import cmsim
    data = {"about": "golden regression of cmsim dynamics; written by "
                     "`python -m tests.golden.test_golden --regenerate`; review the diff before "
                     "committing",
            "cmsim_version": cmsim.__version__, "rtol": RTOL, "cases": {}}
    for name, case in CASES.items():
        start = time.perf_counter()
        run = _run_case(case)
        data["cases"][name] = {"inputs": json.loads(json.dumps(case)),
                               "outputs": summarise(run, case)}
        print(f"{name}: {time.perf_counter() - start:.1f} s", file=sys.stderr)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    tmp.replace(path)
    return data


def measure(names=None):
    """Reproducibility, round-off-proxy and half-step deviations of each case (for the docs)."""
    report = {}
    for name in names or CASES:
        case = CASES[name]
        t0 = time.perf_counter()
        ref = summarise(_run_case(case), case)
        wall = time.perf_counter() - t0
        rows = {"rerun": summarise(_run_case(case), case),
                "perturb_1e-12": summarise(_run_case(case, perturb=1e-12), case),
                "substeps_2": summarise(_run_case(case, substeps=2), case)}
        report[name] = {"wall_s": wall}
        for kind, new in rows.items():
            dev = deviations(ref, new)
            worst = max(dev, key=dev.get)
            report[name][kind] = {"max": dev[worst], "where": worst,
                                  "min": min(dev.values()),
                                  "median": float(np.median(list(dev.values()))),
                                  "all": dev}
            print(f"{name:28s} {kind:14s} max {dev[worst]:.3e} ({worst}) "
                  f"median {report[name][kind]['median']:.3e}", file=sys.stderr)
    return report


def main(argv=None):
    p = argparse.ArgumentParser(description="golden regression fixtures of cmsim dynamics")
    p.add_argument("--regenerate", action="store_true", help=f"rewrite {GOLDEN_PATH}")
    p.add_argument("--measure", type=Path, metavar="JSON",
                   help="measure reproducibility / round-off / half-step deviations")
    p.add_argument("--cases", nargs="*", help="subset of cases for --measure")
    p.add_argument("--out", type=Path, default=GOLDEN_PATH,
                   help="where --regenerate writes (default: the golden file)")
    p.add_argument("--compare", type=Path, nargs=2, metavar=("REF", "NEW"),
                   help="print the largest deviation per case between two golden files")
    args = p.parse_args(argv)
    import cmsim
    print(f"cmsim from {cmsim.__file__}", file=sys.stderr)
    if args.regenerate:
        regenerate(args.out)
    if args.measure:
        args.measure.write_text(json.dumps(measure(args.cases), indent=1))
    if args.compare:
        ref, new = (json.loads(f.read_text())["cases"] for f in args.compare)
        for name in ref:
            dev = deviations(ref[name]["outputs"], new[name]["outputs"])
            worst = max(dev, key=dev.get)
            print(f"{name:28s} max {dev[worst]:.3e} ({worst})")
    if not (args.regenerate or args.measure or args.compare):
        p.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
