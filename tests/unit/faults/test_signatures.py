"""Each fault raises its own signature, the signature grows with severity, a healthy run
shows none of them (issue 16); simulated bearing faults peak where measured CWRU records peak.

Tier (c) behaviour for the signatures (what a condition-monitoring engineer looks for):

* outer race → BPFO and its harmonics in the envelope spectrum of the faulty bearing's force
  and of its housing accelerometer; inner race → BPFI with shaft-rate sidebands; ball →
  2×BSF with FTF sidebands (CWRU 6205 rig model, 1797 rpm, 500 N down);
* eccentricity → a transmission-error component at the shaft rate (the eccentricity itself,
  projected on the line of action) and shaft-rate sidebands around the GMF harmonics;
* crack / spall / breakage of one tooth → a once-per-revolution event in the TSA residual
  (the synchronous average with the GMF harmonics removed: its kurtosis rises) and shaft-rate
  sidebands around the GMF harmonics (paper rig, 1000 rpm, 20 N m, potential-energy table;
  the spall and the crack also on the on-line hybrid contact, model A);

"grows with severity" = strictly increasing over 3 severities; "healthy shows none" = the
healthy level is at most 1/20 (bearing lines) or 1/3 (gear sidebands) of the smallest fault's.

Tier (b) measured data: the envelope spectrum of the simulated accelerometer peaks where the
CWRU drive-end records OR007@6_0 (BPFO) and IR007_0 (BPFI) peak, within 1 % (the slip of
a real bearing; Smith & Randall 2015) — read from ``$CMSIM_DATA`` or ``../shared/datasets``;
skipped when absent. Tier (a): the model's CWRU defect frequencies against the published
ratios 3.5848 / 5.4152 / 2.357 / 0.3983 × shaft rate within 0.5 %.
"""

import functools
import json
import math

import numpy as np
import pytest

import cmsim
from cmsim.dynamics import simulate
from cmsim.faults import FAULT_TYPES, BallDefect, compile_faults, parse_fault
from cmsim.faults.compile import DEFECT_COLUMNS
from cmsim.frequencies import rig_frequencies
from cmsim.measured import data_root
from cmsim.run import Run
from cmsim.sensors import add_sensors
from cmsim.spectra import amplitude_spectrum, envelope_spectrum, kurtogram
from cmsim.spectra.tsa import time_synchronous_average

# ---------------------------------------------------------------------- CWRU bearing rig
CWRU_RPM = 1797.0
FR = CWRU_RPM / 60.0
PUBLISHED = {"bpfo": 3.5848, "bpfi": 5.4152, "bsf": 2.357, "ftf": 0.3983}  # × shaft rate
FORCE_BAND_HZ = (2000.0, 20000.0)


def cwru_rig():
    b = cmsim.RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3, clearance_m=5e-6)
    return cmsim.Rig.rotor_on_bearings(b, cmsim.Rotor(mass_kg=10.0, inertia_kg_m2=0.02))


def cwru_op(rpm=CWRU_RPM):
    return cmsim.OperatingPoint(rpm, radial_load_n=500.0, radial_load_angle_rad=-math.pi / 2)


@functools.lru_cache(maxsize=None)
def bearing_run(fault_text="", rpm=CWRU_RPM, duration_s=1.0):
    """(force run at 48 kHz, accelerometer run at 12 kHz) of the CWRU rig model."""
    faults = (parse_fault(fault_text),) if fault_text else ()
    run = simulate(cwru_rig(), cwru_op(rpm), duration_s, faults=faults, fs_hz=48_000.0, seed=1)
    return run, add_sensors(run, fs_hz=12_000.0, seed=1)


def level(spec, f_hz, bins=2):
    """Largest amplitude within ``bins`` bins of ``f_hz`` (a flat-top line spreads)."""
    df = spec.freq_hz[1] - spec.freq_hz[0]
    near = np.abs(spec.freq_hz - f_hz) <= bins * df
    return float(spec.amplitude[near].max())


def floor(spec, lo=20.0, hi=400.0):
    """Median envelope amplitude between lo and hi (the level between the lines)."""
    band = (spec.freq_hz > lo) & (spec.freq_hz < hi)
    return float(np.median(spec.amplitude[band]))


def peak_hz(spec, lo, hi):
    band = (spec.freq_hz >= lo) & (spec.freq_hz <= hi)
    return float(spec.freq_hz[band][np.argmax(spec.amplitude[band])])


def envelopes(fault_text, rpm=CWRU_RPM, duration_s=1.0):
    """Envelope spectra of F_1b1_y (fixed high band) and accel_1b1_y (kurtogram's band)."""
    run, acc = bearing_run(fault_text, rpm, duration_s)
    env_f = envelope_spectrum(run["F_1b1_y"], run.fs_hz, FORCE_BAND_HZ)
    x = acc["accel_1b1_y"]
    band = kurtogram(x, acc.fs_hz, max_fault_hz=400.0).band_hz
    env_a = envelope_spectrum(x, acc.fs_hz, band)
    return {"F_1b1_y": env_f, "accel_1b1_y": env_a}


#: defect length along the race (ball: on the ball), m. The ball's drop into the defect (the
#: sagitta of the chord on the ball: 0.3, 1.3, 7.9 µm) stays within its static approach (about
#: 8.5 µm for the most loaded ball at 250 N per bearing), the regime where the lost load grows with size (see the saturation test below)
SEVERITIES_M = (1e-4, 2e-4, 5e-4)
DEPTH_M = 2e-4


def _lines(kind):
    if kind == "outer_race":
        return {"BPFO": PUBLISHED["bpfo"] * FR, "2xBPFO": 2 * PUBLISHED["bpfo"] * FR}
    if kind == "inner_race":
        f = PUBLISHED["bpfi"] * FR
        return {"BPFI": f, "BPFI-fr": f - FR, "BPFI+fr": f + FR}
    f = 2 * PUBLISHED["bsf"] * FR
    ftf = PUBLISHED["ftf"] * FR
    return {"2xBSF": f, "2xBSF-FTF": f - ftf, "2xBSF+FTF": f + ftf}


def bearing_signature(kind):
    """{signal: {line: [healthy, sev1, sev2, sev3]}} and the floors of the faulty runs."""
    out, floors = {}, {}
    runs = [envelopes("")] + [envelopes(f"{kind}:bearing=1b1,size_m={s},depth_m={DEPTH_M}")
                              for s in SEVERITIES_M]
    for sig in ("F_1b1_y", "accel_1b1_y"):
        out[sig] = {name: [level(r[sig], f) for r in runs] for name, f in _lines(kind).items()}
        floors[sig] = [floor(r[sig]) for r in runs]
    return out, floors, runs


@pytest.mark.parametrize("kind", ["outer_race", "inner_race", "ball"])
def test_bearing_fault_signature_grows_and_healthy_shows_none(kind):
    table, floors, runs = bearing_signature(kind)
    first = next(iter(_lines(kind)))
    for sig, lines in table.items():
        for name, (healthy, *faulty) in lines.items():
            # every line of the signature stands out of the faulty run's envelope spectrum
            for lv, fl in zip(faulty, floors[sig][1:]):
                assert lv > 5.0 * fl, (sig, name, lv, fl)
            # ... and the healthy run shows none of it
            assert healthy < min(faulty) / 20.0, (sig, name, healthy, faulty)
        grow = lines[first][1:]
        assert all(b > a for a, b in zip(grow, grow[1:])), (sig, first, grow)


@pytest.mark.xfail(strict=True, reason="finding (issue 16): once the ball's drop (31.6 µm "
                   "for 1 mm) exceeds its static approach (6 µm Hertz + 2.5 µm half clearance for the most loaded ball, 250 N per bearing) the ball unloads "
                   "completely in the defect; a longer defect then only lengthens the unloaded "
                   "interval, and the envelope lines of the force stop growing (BPFO 13.1 N at "
                   "0.5 mm, 10.5 N at 1 mm; BPFI 2.83 -> 2.51; 2xBSF 2.67 -> 2.40)")
@pytest.mark.parametrize("kind", ["outer_race", "inner_race", "ball"])
def test_bearing_force_signature_keeps_growing_past_full_unloading(kind):
    first, f = next(iter(_lines(kind).items()))
    lv = [level(envelopes(f"{kind}:bearing=1b1,size_m={s},depth_m={DEPTH_M}")["F_1b1_y"], f)
          for s in (5e-4, 1e-3)]
    assert lv[1] > lv[0], (kind, first, lv)


def test_outer_race_bpfo_is_the_strongest_envelope_line():
    """BPFO dominates the envelope of the faulty bearing's force and accelerometer."""
    for s in SEVERITIES_M:
        env = envelopes(f"outer_race:bearing=1b1,size_m={s},depth_m={DEPTH_M}")
        for sig, spec in env.items():
            f = peak_hz(spec, 5.0, 400.0)
            assert abs(f - PUBLISHED["bpfo"] * FR) <= 2 * spec.freq_hz[1], (s, sig, f)


def test_ball_fault_on_the_other_bearing_leaves_1b1_quiet():
    """The signature sits on the faulty bearing: a ball defect in 1b2 raises 2×BSF there
    far more than in 1b1's force."""
    run, _ = bearing_run(f"ball:bearing=1b2,size_m=1e-3,depth_m={DEPTH_M}")
    f = 2 * PUBLISHED["bsf"] * FR
    own = level(envelope_spectrum(run["F_1b2_y"], run.fs_hz, FORCE_BAND_HZ), f)
    other = level(envelope_spectrum(run["F_1b1_y"], run.fs_hz, FORCE_BAND_HZ), f)
    assert own > 3.0 * other, (own, other)


BALL_TRACK_SIZE_M = 2e-4      # drop 1.3 µm: the line grows in proportion with the depth


def _ball_2bsf(extra=""):
    """2×BSF envelope line of F_1b1_y of a 0.2 mm ball defect with ``extra`` options."""
    env = envelopes(f"ball:bearing=1b1,size_m={BALL_TRACK_SIZE_M},depth_m={DEPTH_M}{extra}")
    return level(env["F_1b1_y"], _lines("ball")["2xBSF"])


def test_ball_defect_off_the_rolling_track_is_silent_and_partly_on_it_is_weaker():
    """A pit off the ball's rolling track never meets the races (the healthy run, to the
    bit); one with half its width inside the contact band (cmsim.faults.bearing.track_share)
    strikes about half as hard."""
    healthy, _ = bearing_run("")
    off, _ = bearing_run(f"ball:bearing=1b1,size_m={BALL_TRACK_SIZE_M},depth_m={DEPTH_M},"
                         f"axis_offset=0.5")
    np.testing.assert_array_equal(off["F_1b1_y"], healthy["F_1b1_y"])
    row = dict(zip(DEFECT_COLUMNS, compile_faults(
        cwru_rig(), [BallDefect("1b1", BALL_TRACK_SIZE_M, DEPTH_M)],
        op=cwru_op()).bearing_defects[0]))
    half_in = round(row["track_rad"] - row["half_width_rad"], 4)
    on, edge = _ball_2bsf(), _ball_2bsf(f",axis_offset={half_in}")
    assert 0.3 * on < edge < 0.7 * on, (on, edge)


def test_wandering_spin_axis_makes_ball_impacts_intermittent():
    """With a wandering spin axis the defect leaves the track for part of the run: the
    2×BSF line drops, and the impacts come and go (the force's band energy over 20 ms
    blocks spreads far more than with the fixed axis on the track)."""
    on = _ball_2bsf()
    wander = _ball_2bsf(",wander_s=0.1")
    assert wander < 0.8 * on, (on, wander)

    def block_spread(extra):
        run, _ = bearing_run(f"ball:bearing=1b1,size_m={BALL_TRACK_SIZE_M},depth_m={DEPTH_M}"
                             f"{extra}")
        x = np.asarray(run["F_1b1_y"], float)
        e = np.diff(x) ** 2                                 # high-passed power
        n = int(0.02 * run.fs_hz)
        blocks = e[:e.size // n * n].reshape(-1, n).sum(axis=1)
        return np.std(blocks) / np.mean(blocks)

    assert block_spread(",wander_s=0.1") > 2.0 * block_spread("")


def test_cwru_characteristic_frequencies_match_published_ratios():
    """Tier (a): the answer key of a run on the CWRU rig model (6205, 1797 rpm)."""
    rig = cwru_rig()
    bf = rig_frequencies(rig, cwru_op()).bearing("1b1")
    got = {"bpfo": bf.bpfo_hz, "bpfi": bf.bpfi_hz, "bsf": bf.bsf_hz, "ftf": bf.ftf_hz}
    for key, ratio in PUBLISHED.items():
        assert got[key] / FR == pytest.approx(ratio, rel=5e-3), key
    run, _ = bearing_run(f"outer_race:bearing=1b1,size_m=5e-4,depth_m={DEPTH_M}")
    (key,) = run.meta["fault_frequencies"].values()
    assert key["bpfo_hz"] / FR == pytest.approx(PUBLISHED["bpfo"], rel=5e-3)


# ---------------------------------------------------------------------- measured CWRU records
def _cwru_dir():
    d = data_root() / "cwru_bearing_12k_de"
    if not (d / "metadata.json").is_file():
        pytest.skip(f"CWRU records not found in {d} (set CMSIM_DATA to the datasets folder)")
    return d


@pytest.mark.parametrize("record, kind, ratio", [
    ("OR007_at6_0.npz", "outer_race", PUBLISHED["bpfo"]),
    ("IR007_0.npz", "inner_race", PUBLISHED["bpfi"]),
])
def test_simulated_envelope_peaks_where_measured_cwru_peaks(record, kind, ratio):
    d = _cwru_dir()
    meta = json.loads((d / "metadata.json").read_text())
    entry = next(r for r in meta["recordings"] if r["file"] == record)
    rpm, fs = float(entry["shaft_speed_rpm"]), float(entry["fs_hz"])
    x = np.load(d / record)["DE"].astype(float)
    env_m = envelope_spectrum(x, fs, kurtogram(x, fs, max_fault_hz=400.0).band_hz)
    f_model = ratio * rpm / 60.0
    lo, hi = 0.9 * f_model, 1.1 * f_model
    f_meas = peak_hz(env_m, lo, hi)
    # 0.007 in wide (0.178 mm), 0.011 in deep EDM pit of the drive-end 6205
    env_s = envelopes(f"{kind}:bearing=1b1,size_m=1.78e-4,depth_m=2.79e-4", rpm, 2.0)
    spec = env_s["accel_1b1_y"]
    f_sim = peak_hz(spec, lo, hi)
    assert level(spec, f_sim) > 5.0 * floor(spec)        # a real line, not noise
    assert abs(f_sim - f_meas) <= max(0.01 * f_meas, 2 * spec.freq_hz[1]), (f_sim, f_meas)


# ---------------------------------------------------------------------- gear faults
GEAR_OP = cmsim.OperatingPoint(1000.0, 20.0)


@functools.lru_cache(maxsize=None)
def gear_run(fault_text="", mesh="potential-energy", duration_s=0.6):
    rig = cmsim.Rig.paper_2016()
    faults = (parse_fault(fault_text),) if fault_text else ()
    return simulate(rig, GEAR_OP, duration_s, faults=faults, fs_hz=20_000.0, seed=1,
                    mesh=mesh)


def _gear_freqs():
    rig = cmsim.Rig.paper_2016()
    f = rig_frequencies(rig, GEAR_OP)
    return f.fr1_hz, f.gmf_hz, rig.gears.driving.n_teeth


def sidebands(run, signal="F_1b1_loa", harmonics=(1, 2)):
    """Sum of the amplitudes at k·GMF ± fr (k in ``harmonics``)."""
    fr, gmf, _ = _gear_freqs()
    spec = amplitude_spectrum(run[signal], run.fs_hz, window="hann")
    return sum(level(spec, k * gmf + s * fr, bins=1) for k in harmonics for s in (-1, 1))


def residual_kurtosis(run, signal):
    """Kurtosis of the TSA residual: the synchronous average over shaft 1 with the GMF
    harmonics (orders k·Z1) removed (Stewart's residual signal)."""
    fr, _, z1 = _gear_freqs()
    avg = time_synchronous_average(run[signal], run.fs_hz, speed_rpm=60.0 * fr).average
    spec = np.fft.rfft(avg - avg.mean())
    spec[np.arange(spec.size) % z1 == 0] = 0.0
    r = np.fft.irfft(spec, avg.size)
    return float(np.mean(r ** 4) / np.mean(r ** 2) ** 2)


def test_eccentricity_te_at_shaft_rate_and_gmf_sidebands():
    fr, _, _ = _gear_freqs()
    healthy = gear_run()
    sb = [sidebands(healthy)]
    for e in (5e-6, 1e-5, 2e-5):
        run = gear_run(f"eccentricity:gear=1,amplitude_m={e}")
        te = level(amplitude_spectrum(run["dte_um"], run.fs_hz, window="flattop"), fr, bins=1)
        # a gear turning about a centre offset by e moves its profile by e along the line
        # of action once per revolution: the TE at the shaft rate is e (µm)
        assert te == pytest.approx(e * 1e6, rel=0.1)
        sb.append(sidebands(run))
    te0 = level(amplitude_spectrum(healthy["dte_um"], healthy.fs_hz, window="flattop"), fr, 1)
    assert te0 < 0.01 * 5.0
    assert sb[0] < sb[1] / 3.0 and all(b > a for a, b in zip(sb[1:], sb[2:])), sb


def test_an_eccentric_gear_s_mass_loads_its_shaft_with_m_e_omega_squared():
    """The body of an eccentric gear turns about its shaft with its mass centre on the offset
    centre: its shaft's bearings carry m·e·Ω² more at the shaft rate, a force rotating with
    the gear (the x and y lines equal, a quarter turn apart), on top of what the contact
    geometry's own change makes (``mass_share=0``). Quasi-static: the shaft rate is far
    below the rig's modes, so the bearings take the whole of it."""
    rig = cmsim.Rig.paper_2016()
    fr, _, _ = _gear_freqs()
    e = 1e-4
    expected = rig.gears.driving.mass_kg * e * (2 * math.pi * fr) ** 2       # 0.88 N

    def shaft_line(share):
        run = gear_run(f"eccentricity:gear=1,amplitude_m={e},mass_share={share}")
        t = np.arange(run["F_1b1_x"].size) / run.fs_hz
        turn = np.exp(-2j * math.pi * fr * t)
        return [2 * np.mean((run[f"F_1b1_{a}"] + run[f"F_1b2_{a}"]) * turn) for a in "xy"]

    whole, toothing = shaft_line(1.0), shaft_line(0.0)
    added = [w - b for w, b in zip(whole, toothing)]
    assert abs(added[0]) == pytest.approx(expected, rel=0.02)
    assert abs(added[1]) == pytest.approx(expected, rel=0.02)
    quarter = abs(np.angle(added[1] / added[0]))
    assert quarter == pytest.approx(math.pi / 2, abs=0.05)
    half = shaft_line(0.5)
    assert abs(half[0] - toothing[0]) == pytest.approx(0.5 * expected, rel=0.03)


TOOTH_FAULTS = {
    "tooth_crack": [f"tooth_crack:gear=1,depth_m={d}" for d in (1.0e-3, 1.75e-3, 2.5e-3)],
    "tooth_spall": [f"tooth_spall:gear=1,width_m={w},depth_m={d}"
                    for w, d in ((5e-4, 1e-5), (1e-3, 2e-5), (2e-3, 3e-5))],
    "tooth_breakage": [f"tooth_breakage:gear=1,lost_height_m={h}"
                       for h in (5e-4, 1.0e-3, 1.5e-3)],
}


@pytest.mark.parametrize("kind", list(TOOTH_FAULTS))
def test_tooth_fault_impulse_in_tsa_residual_and_sidebands(kind):
    healthy = gear_run()
    runs = [gear_run(t) for t in TOOTH_FAULTS[kind]]
    k = [residual_kurtosis(r, "dte_um") for r in [healthy] + runs]
    # once-per-revolution impulse: the residual's kurtosis rises with severity, from the
    # near-Gaussian healthy level
    assert k[0] < 4.0 and k[1] > 1.5 * k[0], k
    assert all(b > a for a, b in zip(k[1:], k[2:])), (kind, k)
    # the bearing force sees the same event
    kf = [residual_kurtosis(r, "F_1b1_loa") for r in [healthy] + runs]
    assert all(x > 1.5 * kf[0] for x in kf[1:]), (kind, kf)
    sb = [sidebands(r) for r in [healthy] + runs]
    assert sb[0] < sb[1] / 1.5 and all(b > a for a, b in zip(sb[1:], sb[2:])), (kind, sb)


@pytest.mark.xfail(strict=True, reason="finding (issue 16): beyond ~1.5 mm of lost tip the "
                   "missing contact spans a large part of the mesh cycle and the TSA residual "
                   "event widens, so its kurtosis falls (22 at 1.5 mm, 8 at 3 mm in the DTE) "
                   "while the sidebands keep growing; kurtosis is a measure of impulsiveness, "
                   "not of severity, once the fault is no longer a short event")
def test_breakage_kurtosis_keeps_rising_to_large_breakage():
    k = [residual_kurtosis(gear_run(f"tooth_breakage:gear=1,lost_height_m={h}"), "dte_um")
         for h in (1.5e-3, 3e-3)]
    assert k[1] > k[0], k


@pytest.mark.slow
def test_spall_shows_on_table_and_online_hybrid_mesh():
    """Tooth separations act on both paths: the spall's residual kurtosis and sidebands on
    the potential-energy table and on the on-line hybrid contact (model A) agree."""
    text = TOOTH_FAULTS["tooth_spall"][1]
    for mesh in ("potential-energy", "hybrid"):
        healthy, run = gear_run("", mesh, 0.4), gear_run(text, mesh, 0.4)
        assert run.meta["mesh"] == ("hybrid" if mesh == "hybrid" else "table")
        k0, k1 = residual_kurtosis(healthy, "dte_um"), residual_kurtosis(run, "dte_um")
        assert k1 > 2.0 * k0, (mesh, k0, k1)
        assert sidebands(run) > 10.0 * sidebands(healthy), mesh
    pe, hy = (sidebands(gear_run(text, m, 0.4)) for m in ("potential-energy", "hybrid"))
    assert hy == pytest.approx(pe, rel=0.3)


@pytest.mark.slow
def test_crack_on_online_hybrid_mesh_matches_the_tables():
    """A crack weakens its pair on the on-line contact solve too (model A: the factor f
    becomes the extra compliance (1/f − 1)/k in series with that contact), and models A and
    B (the default tables at the run's torque) feel it alike: measured 1.7 % apart in the
    residual kurtosis and 5 % in the sidebands at 2.5 mm."""
    text = TOOTH_FAULTS["tooth_crack"][2]
    got = {}
    for mesh in (None, "hybrid"):
        healthy, run = gear_run("", mesh, 0.4), gear_run(text, mesh, 0.4)
        assert run.meta["mesh"] == ("hybrid" if mesh == "hybrid" else "table")
        k0, k1 = residual_kurtosis(healthy, "dte_um"), residual_kurtosis(run, "dte_um")
        sb0, sb1 = sidebands(healthy), sidebands(run)
        assert k1 > 5.0 * k0 and sb1 > 3.0 * sb0, (mesh, k0, k1, sb0, sb1)
        got[mesh] = (k1, sb1)
    assert got["hybrid"][0] == pytest.approx(got[None][0], rel=0.15)
    assert got["hybrid"][1] == pytest.approx(got[None][1], rel=0.15)


@pytest.mark.slow
def test_crack_on_the_default_mesh_tables():
    """The default mesh (hybrid FE tables at the run's torque, model B) feels a crack."""
    healthy = gear_run("", None, 0.6)
    run = gear_run(TOOTH_FAULTS["tooth_crack"][2], None, 0.6)
    assert residual_kurtosis(run, "dte_um") > 2.0 * residual_kurtosis(healthy, "dte_um")
    assert sidebands(run) > 2.0 * sidebands(healthy)


# ---------------------------------------------------------------------- CLI
def test_cli_fault_and_ramp_reach_the_run(tmp_path, capsys):
    """--fault, --faults and a rig file's [[faults]] reach the run meta; --ramp-to-rpm makes
    the tacho pulse faster at the end than at the start."""
    from cmsim.cli import main
    from cmsim.cli.options import FAULT_NAMES
    assert sorted(FAULT_NAMES) == sorted(FAULT_TYPES)
    rig = cwru_rig()
    rig.save(tmp_path / "rig.toml", faults=(parse_fault(
        "inner_race:bearing=1b2,size_m=5e-4,depth_m=1e-4"),))
    (tmp_path / "f.toml").write_text('[[faults]]\ntype = "ball"\nbearing = "1b1"\n'
                                     'size_m = 5e-4\ndepth_m = 1e-4\n')
    out = tmp_path / "run.npz"
    argv = ["simulate", "--rig", tmp_path / "rig.toml", "--speed-rpm", "600",
            "--radial-load-n", "500", "--duration-s", "0.5", "--fs-hz", "24000",
            "--fault", "outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4",
            "--faults", tmp_path / "f.toml", "--ramp-to-rpm", "1800", "--sensors",
            "--out", out, "--json"]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    assert [f.split("@")[0] for f in res["faults"]] == ["inner_race", "ball", "outer_race"]
    assert res["speed_profile"]["speeds_rpm"] == [600.0, 1800.0]
    run = Run.load(out)
    assert len(run.meta["fault_frequencies"]) == 3
    tacho = run["tacho"]
    edges = np.flatnonzero((tacho[1:] > 0.5 * tacho.max()) & (tacho[:-1] <= 0.5 * tacho.max()))
    gaps = np.diff(edges) / run.fs_hz
    # speed at the first and last pulse gaps against the ramp (600 → 1800 rpm over 0.55 s)
    assert 60.0 / gaps[0] < 60.0 / gaps[-1]
    assert 60.0 / gaps[-1] == pytest.approx(1800.0, rel=0.1)
