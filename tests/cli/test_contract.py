"""The CLI contract, for every command: a catalogue of bad inputs and what each must give.

Tier (c) behaviour (issue 10): exit 2 for bad input (3 for a diverged run), exactly one error
line on stderr naming the option as typed (``--top``, not ``max_peaks``) and, for a numeric
option, its allowed range (the rows run as on a cold numba cache: bad input is refused before
the compile notice, a diverged run may follow it); with ``--json`` exactly one JSON object on
stdout (``error``, ``status``, ``option``); never a traceback; no file left behind in the
working directory.

To add a command: give it a base command line in ``BASE`` (its required arguments, valid) and
its hand-written rows in ``CATALOGUE``; every numeric option then gets the generated rows
(``nan``, ``inf``, ``abc``) and the coverage test checks that the option has a range.
Run ids are ``<command>-<what>``.
"""

import argparse
import json
import types
import math
import re
import subprocess
import sys
import wave
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import cmsim
from cmsim.cli import app, build_parser, contract, main
from cmsim.datasets.manifest import write_row
from cmsim.machine import Background, Machine, TransferPath
from cmsim.rig import Rig
from cmsim.run import Run

TABLES = Path(cmsim.__file__).parent / "data" / "paper_2016_hybrid_tables.npz"


@dataclass(frozen=True)
class Row:
    """One bad input: ``argv`` (``{name}`` = a fixture path), the exit status, and the words
    the one-line message must hold (the option as typed first). ``needs_model``: the bound
    is the model's (the torque its shafts carry), so the refusal may follow the progress
    lines of the model build it needed (the FE body of the gears on a cold cache)."""

    id: str
    argv: tuple
    names: tuple
    status: int = 2
    numeric: bool = False
    needs_model: bool = False


def R(id, argv, *names, status=2, numeric=False, needs_model=False):
    return Row(id, tuple(argv.split()), names, status, numeric, needs_model)


# every command with the required arguments of a valid call ({run}, {sweep}: fixtures)
BASE = {
    "simulate": "simulate --speed-rpm 1000 --duration-s 0.01",
    "modes": "modes --torque-nm 10",
    "mesh-table": "mesh-table --torque-nm 10",
    "spectrum": "spectrum {run}",
    "sweep": "sweep --speed-rpm 1000 --out {work}/sw",
    "report": "report {sweep}",
    "evaluate": "evaluate {empty_dir} --algorithm envelope",
    "compare": "compare {record}",
    "dataset": "dataset {ds_spec} --out {work}/ds",
    "export": "export {run} --format npz --out {work}/ex --channels F_1b1_loa",
    "losses": "losses --speed-rpm 1000 --torque-nm 10",
    "calibrate": "calibrate {record} --out {work}/machine.toml",
    "import": "import {empty_dir} --out {work}/metadata.json",
}

CATALOGUE = [
    # ---- simulate: issue items 4, 7, 8 and kin
    R("simulate-seed-negative", "simulate --speed-rpm 1000 --seed -1", "--seed", numeric=True),
    R("simulate-seed-float", "simulate --speed-rpm 1000 --seed 1.5", "--seed", numeric=True),
    R("simulate-speed-zero", "simulate --speed-rpm 0", "--speed-rpm", numeric=True),
    R("simulate-speed-missing", "simulate --torque-nm 5", "--speed-rpm"),
    R("simulate-speed-no-value", "simulate --speed-rpm", "--speed-rpm"),
    R("simulate-unknown-option", "simulate --speed-rpm 1000 --torque 5", "--torque"),
    R("simulate-torque-huge", "simulate --speed-rpm 1000 --torque-nm 1e7", "--torque-nm",
      numeric=True),
    R("simulate-radial-negative", "simulate --speed-rpm 1000 --radial-load-n -5",
      "--radial-load-n", numeric=True),
    R("simulate-substeps-zero", "simulate --speed-rpm 1000 --substeps 0", "--substeps",
      numeric=True),
    R("simulate-fs-low", "simulate --speed-rpm 1000 --fs-hz 10", "--fs-hz", numeric=True),
    R("simulate-duration-zero", "simulate --speed-rpm 1000 --duration-s 0", "--duration-s",
      numeric=True),
    R("simulate-duration-memory", "simulate --speed-rpm 1000 --duration-s 600 --fs-hz 1e7",
      "--duration-s"),
    R("simulate-warmup-negative", "simulate --speed-rpm 1000 --warmup-s -1", "--warmup-s",
      numeric=True),
    R("simulate-clearance-parse", "simulate --speed-rpm 1000 --clearance-m 0.02",
      "--clearance-m", numeric=True),
    R("simulate-clearance-bearing", "simulate --speed-rpm 1000 --clearance-m 0.0009",
      "--clearance-m", numeric=True),
    R("simulate-friction", "simulate --speed-rpm 1000 --friction 0.5", "--friction",
      numeric=True),
    R("simulate-friction-bearing-rig", "simulate --speed-rpm 1000 --friction 0.1 --rig "
      "{bearing_rig}", "--friction"),
    R("simulate-cage-slip", "simulate --speed-rpm 1000 --cage-slip 0.5", "--cage-slip",
      numeric=True),
    R("simulate-ball-jitter", "simulate --speed-rpm 1000 --ball-jitter-rad 1", "--ball-jitter-rad",
      numeric=True),
    R("simulate-slip-correlation", "simulate --speed-rpm 1000 --slip-correlation-s 0",
      "--slip-correlation-s", numeric=True),
    R("simulate-rig-directory", "simulate --speed-rpm 1000 --rig {work}", "--rig"),
    R("simulate-rig-missing", "simulate --speed-rpm 1000 --rig {work}/none.toml", "--rig"),
    R("simulate-rig-text", "simulate --speed-rpm 1000 --rig {text}", "--rig"),
    R("simulate-rig-binary", "simulate --speed-rpm 1000 --rig {run}", "--rig"),
    R("simulate-rig-empty", "simulate --speed-rpm 1000 --rig {empty}", "--rig", "missing key"),
    R("simulate-rig-missing-key", "simulate --speed-rpm 1000 --rig {rig_no_balls}", "--rig",
      "shafts[0].bearing_1.n_balls"),
    R("simulate-rig-bool-mass", "simulate --speed-rpm 1000 --rig {rig_bool_mass}", "--rig",
      "gears.driving.mass_kg"),
    R("simulate-rig-two-modules", "simulate --speed-rpm 1000 --rig {rig_two_modules}", "--rig",
      "module_mm"),
    R("simulate-rig-strings-pair", "simulate --speed-rpm 1000 --rig {rig_strings}", "--rig",
      "shafts[1].flexural_stiffness_n_per_m"),
    R("simulate-rig-stiffness-1e20", "simulate --speed-rpm 1000 --rig {rig_stiff}", "--rig",
      "shafts[0].flexural_stiffness_n_per_m", numeric=True),
    R("simulate-rig-teeth-100000", "simulate --speed-rpm 1000 --rig {rig_teeth}", "--rig",
      "gears.driven.n_teeth", numeric=True),
    R("simulate-rig-nan-clearance", "simulate --speed-rpm 1000 --rig {rig_nan}", "--rig",
      "shafts[1].bearing_2.clearance_m", numeric=True),
    R("simulate-rig-unknown-key", "simulate --speed-rpm 1000 --rig {rig_unknown}", "--rig",
      "modul_m"),
    R("simulate-out-directory", "simulate --speed-rpm 1000 --out {work}", "--out"),
    R("simulate-out-not-npz", "simulate --speed-rpm 1000 --duration-s 0.01 --out {work}/r.txt",
      "--out", ".npz"),
    R("simulate-out-no-parent", "simulate --speed-rpm 1000 --out {work}/no/run.npz", "--out"),
    R("simulate-mesh-choice", "simulate --speed-rpm 1000 --mesh bogus", "--mesh"),
    R("simulate-mesh-and-table", "simulate --speed-rpm 1000 --mesh potential-energy "
      "--mesh-table {tables}", "--mesh"),
    R("simulate-mesh-table-run-file", "simulate --speed-rpm 1000 --mesh-table {run}",
      "--mesh-table"),
    R("simulate-mesh-table-text", "simulate --speed-rpm 1000 --mesh-table {text}", "--mesh-table"),
    R("simulate-mesh-table-torque", "simulate --speed-rpm 1000 --torque-nm 500 --mesh-table "
      "{tables}", "--torque-nm", numeric=True),
    R("simulate-table-torque-outside", "simulate --speed-rpm 1000 --mesh-table {tables} "
      "--table-torque-nm 1000", "--table-torque-nm", numeric=True),
    R("simulate-table-torque-alone", "simulate --speed-rpm 1000 --table-torque-nm 10",
      "--table-torque-nm"),
    R("simulate-sensor-fs-above-fs", "simulate --speed-rpm 1000 --fs-hz 20000 --sensor-fs-hz "
      "40000", "--sensor-fs-hz", numeric=True),
    # ---- simulate: faults and speed profiles (issue 16)
    R("simulate-fault-unknown-name", "simulate --speed-rpm 1000 --fault bogus:size_m=1e-3",
      "--fault", "type", "outer_race"),
    R("simulate-fault-unknown-bearing", "simulate --speed-rpm 1000 --fault "
      "outer_race:bearing=9z9,size_m=1e-3,depth_m=1e-4", "--fault", "bearing", "1b1"),
    R("simulate-fault-unknown-gear", "simulate --speed-rpm 1000 --fault "
      "tooth_crack:gear=3,depth_m=1e-3", "--fault", "gear", "1 (driving) or 2"),
    R("simulate-fault-gear-on-bearing-rig", "simulate --speed-rpm 1000 --rig {bearing_rig} "
      "--fault eccentricity:gear=1,amplitude_m=1e-5", "--fault", "gear"),
    R("simulate-fault-race-too-large", "simulate --speed-rpm 1000 --fault "
      "outer_race:bearing=1b1,size_m=0.05,depth_m=1e-4", "--fault", "size_m", "ball spacing",
      numeric=True),
    R("simulate-fault-ball-too-large", "simulate --speed-rpm 1000 --fault "
      "ball:bearing=2b2,size_m=0.02,depth_m=1e-4", "--fault", "size_m", "ball diameter",
      numeric=True),
    R("simulate-fault-crack-too-deep", "simulate --speed-rpm 1000 --fault "
      "tooth_crack:gear=1,depth_m=5e-3", "--fault", "depth_m", numeric=True),
    R("simulate-fault-breakage-too-high", "simulate --speed-rpm 1000 --fault "
      "tooth_breakage:gear=2,lost_height_m=0.01", "--fault", "lost_height_m", numeric=True),
    R("simulate-fault-tooth-index", "simulate --speed-rpm 1000 --fault "
      "tooth_spall:gear=1,width_m=1e-3,depth_m=1e-5,tooth=99", "--fault", "tooth",
      numeric=True),
    R("simulate-fault-negative-size", "simulate --speed-rpm 1000 --fault "
      "inner_race:bearing=1b1,size_m=-1e-3,depth_m=1e-4", "--fault", "size_m", numeric=True),
    R("simulate-fault-negative-depth", "simulate --speed-rpm 1000 --fault "
      "tooth_spall:gear=1,width_m=1e-3,depth_m=-1e-5", "--fault", "depth_m", numeric=True),
    R("simulate-fault-missing-depth", "simulate --speed-rpm 1000 --fault "
      "outer_race:bearing=1b1,size_m=1e-3", "--fault", "depth_m"),
    R("simulate-fault-not-key-value", "simulate --speed-rpm 1000 --fault outer_race:bearing",
      "--fault", "key=value"),
    R("simulate-fault-unknown-parameter", "simulate --speed-rpm 1000 --fault "
      "outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4,width_m=1", "--fault", "width_m",
      "allowed"),
    R("simulate-fault-speed-wobble-negative", "simulate --speed-rpm 1000 --fault "
      "speed_fluctuation:relative_amplitude=1.5,frequency_hz=5", "--fault",
      "relative_amplitude", numeric=True),
    R("simulate-faults-file-missing", "simulate --speed-rpm 1000 --faults {work}/none.toml",
      "--faults"),
    R("simulate-faults-file-text", "simulate --speed-rpm 1000 --faults {text}", "--faults",
      "TOML"),
    R("simulate-faults-file-bad-entry", "simulate --speed-rpm 1000 --faults {faults_bad}",
      "--faults", "faults[1]", "size_m", numeric=True),
    R("simulate-faults-file-unknown-bearing", "simulate --speed-rpm 1000 --rig {bearing_rig} "
      "--faults {faults_gear}", "--faults", "faults[0]", "bearing", "1b1"),
    R("simulate-rig-bad-faults", "simulate --speed-rpm 1000 --rig {rig_bad_faults}", "--rig",
      "type", "outer_race"),
    R("simulate-ramp-negative", "simulate --speed-rpm 1000 --ramp-to-rpm -100",
      "--ramp-to-rpm", numeric=True),
    R("simulate-ramp-zero", "simulate --speed-rpm 1000 --ramp-to-rpm 0", "--ramp-to-rpm",
      numeric=True),
    R("simulate-ramp-s-zero", "simulate --speed-rpm 1000 --ramp-to-rpm 2000 --ramp-s 0",
      "--ramp-s", numeric=True),
    R("simulate-ramp-s-alone", "simulate --speed-rpm 1000 --ramp-s 1", "--ramp-s",
      "--ramp-to-rpm"),
    R("simulate-diverges", "simulate --speed-rpm 100 --torque-nm 100 --fs-hz 2000 --substeps 1 "
      "--warmup-s 0 --duration-s 0.2", "--substeps", status=3),
    # ---- modes
    R("modes-positions", "modes --torque-nm 10 --positions 3", "--positions", numeric=True),
    R("modes-torque-negative", "modes --torque-nm -5", "--torque-nm", numeric=True),
    R("modes-torque-missing", "modes", "--torque-nm"),
    R("simulate-speed-negative-exponent", "simulate --speed-rpm -1e308", "--speed-rpm",
      "got -1e+308", numeric=True),
    R("modes-bearing-rig-unloaded", "modes --torque-nm 0 --rig {bearing_rig}",
      "--radial-load-n", "> 0 N", "without gears"),
    R("modes-rig-bool-mass", "modes --torque-nm 10 --rig {rig_bool_mass}", "--rig", "mass_kg"),
    R("modes-mesh-table-text", "modes --torque-nm 10 --mesh-table {text}", "--mesh-table"),
    # ---- mesh-table
    R("mesh-table-speed-negative", "mesh-table --torque-nm 10 --speed-rpm -1", "--speed-rpm",
      numeric=True),
    R("mesh-table-torque-zero", "mesh-table --torque-nm 0", "--torque-nm", numeric=True),
    R("mesh-table-steps", "mesh-table --torque-nm 10 --steps 2", "--steps", numeric=True),
    R("mesh-table-method", "mesh-table --torque-nm 10 --method fe", "--method"),
    R("mesh-table-out-directory", "mesh-table --torque-nm 10 --out {work}", "--out"),
    R("mesh-table-bearing-rig", "mesh-table --torque-nm 10 --rig {bearing_rig}", "--rig"),
    # ---- spectrum
    R("spectrum-text-file", "spectrum {text}", "RECORD"),
    R("spectrum-empty-file", "spectrum {empty}", "RECORD"),
    R("spectrum-toml-file", "spectrum {rig_ok}", "RECORD"),
    R("spectrum-directory", "spectrum {work}", "RECORD"),
    R("spectrum-missing", "spectrum {work}/none.npz", "RECORD"),
    R("spectrum-meta-not-json", "spectrum {bad_meta}", "RECORD"),
    R("spectrum-meta-bad-rig", "spectrum {bad_rig_meta}", "RECORD"),
    R("spectrum-table-file", "spectrum {tables}", "RECORD"),
    R("spectrum-signal", "spectrum {run} --channel nosuch", "--channel"),
    R("spectrum-signal-and-channel", "spectrum {run} --channel a --signal b", "--signal",
      "old name of --channel"),
    R("spectrum-bearing", "spectrum {run} --bearing 9z9", "--bearing"),
    R("spectrum-kind", "spectrum {run} --kind cepstrum", "--kind"),
    R("spectrum-band-reversed", "spectrum {run} --kind envelope --band-hz 500 100", "--band-hz"),
    R("spectrum-band-amplitude", "spectrum {run} --band-hz 100 500", "--band-hz"),
    R("spectrum-resolution", "spectrum {run} --resolution-hz 0.001", "--resolution-hz"),
    R("spectrum-top-zero", "spectrum {run} --top 0", "--top", numeric=True),
    R("spectrum-threshold", "spectrum {run} --threshold-db -3", "--threshold-db", numeric=True),
    R("spectrum-plot-directory", "spectrum {run} --plot {work}", "--plot"),
    R("spectrum-plot-no-parent", "spectrum {run} --plot {work}/no/x.png", "--plot"),
    # ---- sweep
    R("sweep-out-file", "sweep --speed-rpm 1000 --out {text}", "--out"),
    R("sweep-out-missing", "sweep --speed-rpm 1000", "--out"),
    R("sweep-torque-negative", "sweep --speed-rpm 1000 --torque-nm -1 --out {work}/s",
      "--torque-nm", numeric=True),
    R("sweep-workers-zero", "sweep --speed-rpm 1000 --workers 0 --out {work}/s", "--workers",
      numeric=True),
    # the one bound of RANGES["workers"] (the command once took 1024, the API 256)
    R("sweep-workers-over", "sweep --speed-rpm 1000 --workers 257 --out {work}/s", "--workers",
      "256", numeric=True),
    R("sweep-seed-policy", "sweep --speed-rpm 1000 --seed-policy each --out {work}/s",
      "--seed-policy"),
    R("sweep-torque-bearing-rig", "sweep --speed-rpm 1000 --torque-nm 10 --rig {bearing_rig} "
      "--out {work}/s", "--torque-nm"),
    R("sweep-radial-gear-rig", "sweep --speed-rpm 1000 --radial-load-n 10 --out {work}/s",
      "--radial-load-n"),
    R("sweep-radial-negative", "sweep --speed-rpm 1000 --radial-load-n -10 --rig {bearing_rig} "
      "--out {work}/s", "--radial-load-n", numeric=True),
    R("sweep-mesh-table-text", "sweep --speed-rpm 1000 --mesh-table {text} --out {work}/s",
      "--mesh-table"),
    R("sweep-mesh-table-torque", "sweep --speed-rpm 1000 --torque-nm 10 5000 --mesh-table "
      "{tables} --out {work}/s", "--torque-nm", numeric=True),
    R("sweep-clearance", "sweep --speed-rpm 1000 --clearance-m 0.002 --out {work}/s",
      "--clearance-m", numeric=True),
    R("sweep-rig-missing-key", "sweep --speed-rpm 1000 --rig {rig_no_balls} --out {work}/s",
      "--rig", "shafts[0].bearing_1.n_balls"),
    # ---- report
    R("report-missing-dir", "report {work}/none", "DIR"),
    R("report-file", "report {text}", "DIR"),
    R("report-empty-dir", "report {empty_dir}", "DIR"),
    R("report-corrupted-run", "report {corrupt_sweep}", "DIR", "corrupted"),
    R("report-top", "report {sweep} --top 0", "--top", numeric=True),
    R("report-max-hz", "report {sweep} --max-hz -1", "--max-hz", numeric=True),
    R("report-max-hz-nyquist", "report {sweep} --max-hz 1e6", "--max-hz", numeric=True),
    R("report-signal", "report {sweep} --signal nosuch", "--signal"),
    # ---- evaluate
    R("evaluate-missing-dir", "evaluate {work}/none --algorithm envelope", "DIR"),
    R("evaluate-dir-is-file", "evaluate {text} --algorithm envelope", "DIR"),
    R("evaluate-not-a-dataset", "evaluate {empty_dir} --algorithm envelope", "DIR"),
    R("evaluate-algorithm-missing", "evaluate {empty_dir}", "--algorithm"),
    R("evaluate-algorithm-unknown", "evaluate {empty_dir} --algorithm nosuch", "--algorithm"),
    R("evaluate-algorithm-module", "evaluate {empty_dir} --algorithm nosuch_mod_xyz:f",
      "--algorithm"),
    R("evaluate-algorithm-function", "evaluate {empty_dir} --algorithm cmsim.rig:nosuch",
      "--algorithm"),
    R("evaluate-algorithm-file", "evaluate {empty_dir} --algorithm {work}/none.py:f",
      "--algorithm"),
    R("evaluate-report-directory", "evaluate {empty_dir} --algorithm envelope --report {work}",
      "--report"),
    R("evaluate-report-no-parent", "evaluate {empty_dir} --algorithm envelope --report "
      "{work}/no/x.html", "--report"),
    R("evaluate-dir-missing", "evaluate --algorithm envelope", "DIR"),
    R("evaluate-train-missing-dir", "evaluate --train {work}/none --test {empty_dir} "
      "--classifier forest", "--train"),
    R("evaluate-train-not-a-dataset", "evaluate --train {empty_dir} --test {empty_dir} "
      "--classifier forest", "--train"),
    R("evaluate-train-and-dir", "evaluate {empty_dir} --algorithm envelope --train {empty_dir}",
      "--train"),
    R("evaluate-test-missing", "evaluate --train {empty_dir} --classifier forest", "--test"),
    R("evaluate-test-is-file", "evaluate --train {empty_dir} --test {text} --classifier forest",
      "--test"),
    R("evaluate-classifier-missing", "evaluate --train {empty_dir} --test {empty_dir}",
      "--classifier"),
    R("evaluate-classifier-unknown", "evaluate --train {empty_dir} --test {empty_dir} "
      "--classifier nosuch", "--classifier"),
    R("evaluate-window-small", "evaluate --train {empty_dir} --test {empty_dir} --classifier "
      "forest --window 3", "--window", numeric=True),
    R("evaluate-max-test-windows-zero", "evaluate --train {empty_dir} --test {empty_dir} "
      "--classifier forest --max-test-windows 0", "--max-test-windows", numeric=True),
    # ---- dataset
    R("dataset-spec-missing", "dataset {work}/none.toml --out {work}/d", "SPEC"),
    R("dataset-spec-directory", "dataset {work} --out {work}/d", "SPEC"),
    R("dataset-spec-text", "dataset {text} --out {work}/d", "SPEC"),
    R("dataset-spec-rig-file", "dataset {rig_ok} --out {work}/d", "SPEC", "format_version",
      "rig or machine file"),
    R("dataset-spec-zero-records", "dataset {ds_zero} --out {work}/d", "SPEC",
      "dataset.records"),
    R("dataset-spec-unknown-fault", "dataset {ds_bad_fault} --out {work}/d", "SPEC",
      "faults.types[0].type"),
    R("dataset-spec-unknown-key", "dataset {ds_unknown_key} --out {work}/d", "SPEC",
      "sensor.chanels"),
    R("dataset-out-file", "dataset {ds_spec} --out {text}", "--out"),
    # ---- export (issue 28)
    R("export-format-unknown", "export {run} --format mp3 --out {work}/ex", "--format",
      "csv", "npz", "mat", "tdms"),
    R("export-channel-unknown", "export {gen_ds} --format csv --out {work}/ex --channels nope",
      "--channels", "'nope'", "accel_1b1_y"),
    R("export-run-channel-unknown", "export {run} --format csv --out {work}/ex --channels "
      "accel_1b1_y", "--channels", "available", "F_1b1_loa"),
    R("export-run-nothing-measurable", "export {run} --format csv --out {work}/ex",
      "--channels", "real machine", "dte_um"),
    R("export-out-exists", "export {gen_ds} --format npz --out {work}", "--out", "--force"),
    R("export-out-file", "export {gen_ds} --format npz --out {text}", "--out"),
    R("export-source-folder", "export {empty_dir} --format npz --out {work}/ex",
      "RUN|DATASET", "dataset directory"),
    R("export-source-text", "export {text} --format npz --out {work}/ex", "RUN|DATASET"),
    R("export-source-not-a-run", "export {bad_meta} --format npz --out {work}/ex "
      "--channels F_1b1_loa", "RUN|DATASET"),
    R("export-window-of-a-run", "export {run} --format csv --out {work}/ex --channels "
      "F_1b1_loa --window 64", "--window", "parquet"),
    R("export-run-as-parquet", "export {run} --format parquet --out {work}/ex --channels "
      "F_1b1_loa", "--format", "windowed layout of a dataset", "npz"),
    R("export-group-by-of-a-run", "export {run} --format csv --out {work}/ex --channels "
      "F_1b1_loa --group-by rig_name", "--group-by", "dataset"),
    R("export-out-is-the-source", "export {gen_ds} --format csv --out {gen_ds} --force",
      "--out", "source"),
    R("export-out-in-the-source", "export {gen_ds} --format csv --out {gen_ds}/records "
      "--force", "--out", "source"),
    R("export-window-too-long", "export {gen_ds} --format parquet --out {work}/ex "
      "--window 100000000", "--window", "record length"),
    R("export-fractions-sum", "export {gen_ds} --format csv --out {work}/ex --fractions "
      "0.5 0.5 0.5", "--fractions", "sum"),
    R("export-group-by-unknown", "export {gen_ds} --format csv --out {work}/ex --group-by "
      "nope", "--group-by", "record_id"),
    R("dataset-out-missing", "dataset {ds_spec}", "--out"),
    R("dataset-workers-zero", "dataset {ds_spec} --out {work}/d --workers 0", "--workers",
      numeric=True),
    R("dataset-workers-over", "dataset {ds_spec} --out {work}/d --workers 257", "--workers",
      "256", numeric=True),
    # ---- losses
    R("losses-speed-zero", "losses --speed-rpm 0 --torque-nm 10", "--speed-rpm", numeric=True),
    R("losses-torque-missing", "losses --speed-rpm 1000", "--torque-nm"),
    R("losses-roughness-zero", "losses --speed-rpm 1000 --torque-nm 10 --roughness-m 0",
      "--roughness-m", numeric=True),
    R("losses-pressure-negative", "losses --speed-rpm 1000 --torque-nm 10 --air-pressure-pa -1",
      "--air-pressure-pa", numeric=True),
    R("losses-jet-nan", "losses --speed-rpm 1000 --torque-nm 10 --oil-jet-kg-s nan",
      "--oil-jet-kg-s", numeric=True),
    R("losses-plot-dir", "losses --speed-rpm 1000 --torque-nm 10 --plot {work}", "--plot"),
    R("losses-rig-text", "losses --speed-rpm 1000 --torque-nm 10 --rig {text}", "--rig"),
    # ---- compare
    R("compare-machine-missing", "compare {record} --machine {work}/none.toml", "--machine"),
    R("compare-machine-text", "compare {record} --machine {text}", "--machine"),
    R("compare-machine-other-channel", "compare {record} --machine {machine_other}",
      "--machine", "'a1'"),
    # issue 48: --rig beside --machine replaced the machine's geometry without a word
    R("compare-rig-not-the-machines", "compare {record} --machine {machine_other} "
      "--rig {rig_cwru}", "--rig", "machine"),
    R("compare-span-reversed", "compare {record} --span 1 0.5", "--span"),
    R("calibrate-missing-out", "calibrate {record}", "--out"),
    R("calibrate-record-missing", "calibrate {work}/none.npz --out {work}/m.toml", "BASELINE",
      "does not exist"),
    R("calibrate-span-reversed", "calibrate {record} --span 1 0.5 --out {work}/m.toml",
      "--span"),
    R("calibrate-span-negative", "calibrate {record} --span -1 0.5 --out {work}/m.toml",
      "--span", numeric=True),
    R("calibrate-out-directory", "calibrate {record} --out {work}", "--out"),
    R("calibrate-resample-above-the-rate", "calibrate {record} --resample-hz 96000 --out "
      "{work}/m.toml", "--resample-hz", "at most the baseline's rate"),
    R("calibrate-resample-no-fraction", "calibrate {record} --resample-hz 7777.7 --out "
      "{work}/m.toml", "--resample-hz", "not a fraction"),
    R("calibrate-resample-negative", "calibrate {record} --resample-hz -5 --out "
      "{work}/m.toml", "--resample-hz", numeric=True),
    R("calibrate-out-exists", "calibrate {record} --out {text}", "--out", "--force"),
    R("calibrate-out-is-the-rig", "calibrate {record} --rig {rig_ok} --out {rig_ok} --force",
      "--out", "--rig"),
    R("simulate-machine-missing", "simulate --speed-rpm 1000 --machine {work}/none.toml",
      "--machine"),
    R("compare-record-missing-arg", "compare", "RECORD"),
    R("compare-record-missing", "compare {work}/none.npz", "RECORD", "does not exist"),
    R("compare-no-metadata", "compare {run}", "RECORD", "metadata.json"),
    R("compare-channel", "compare {record} --channel nosuch", "--channel", "DE"),
    R("compare-budget-low", "compare {record} --budget 2", "--budget", numeric=True),
    R("compare-seed-negative", "compare {record} --seed -1", "--seed", numeric=True),
    R("compare-workers-zero", "compare {record} --workers 0", "--workers", numeric=True),
    R("compare-rig-missing", "compare {record} --rig {work}/none.toml", "--rig"),
    R("compare-rig-text", "compare {record} --rig {text}", "--rig"),
    R("compare-report-file", "compare {record} --report {text}", "--report"),
    # ---- files, user code and the cluster (issue 26: evaluate, dataset)
    R("evaluate-algorithm-raises-on-every-record", "evaluate {gen_ds} --algorithm "
      "{algo}:boom", "--algorithm", "answered no record", "ValueError: nope"),
    R("evaluate-algorithm-calls-sys-exit", "evaluate {gen_ds} --algorithm {algo}:leave",
      "--algorithm", "answered no record", "sys.exit(1)"),
    R("evaluate-algorithm-exits-on-import", "evaluate {gen_ds} --algorithm {algo_exit}:f",
      "--algorithm", "SystemExit"),
    R("evaluate-every-record-truncated", "evaluate {gen_truncated} --algorithm envelope",
      "DIR", "no record could be read", "BadZipFile"),
    R("evaluate-every-record-deleted", "evaluate {gen_deleted} --algorithm envelope", "DIR",
      "no record could be read", "missing"),
    R("evaluate-manifest-corrupt", "evaluate {gen_bad_manifest} --algorithm envelope", "DIR",
      "manifest.parquet is corrupt", "remove it"),
    R("evaluate-manifest-foreign", "evaluate {gen_foreign_manifest} --algorithm envelope",
      "DIR", "manifest.parquet is not a cmsim manifest"),
    R("dataset-resume-manifest-corrupt", "dataset {ds_spec} --out {gen_bad_manifest}", "--out",
      "manifest.parquet is corrupt", "remove it"),
    R("dataset-scheduler-refused", "dataset {ds_spec} --out {work}/dask --scheduler "
      "tcp://127.0.0.1:1", "--scheduler", "cannot connect"),
    R("dataset-scheduler-not-an-address", "dataset {ds_spec} --out {work}/dask2 --scheduler "
      "tcp://nohost", "--scheduler", "address"),
    # ---- measured recordings that are bad (issue 26: cmsim/measured/, one reader for all)
    R("compare-record-truncated", "compare {rec_truncated}", "RECORD", "truncated",
      "rec.npz"),
    R("compare-metadata-fs-text", "compare {rec_fs_text}", "RECORD", "metadata.json",
      "fs_hz", "'12k'", numeric=True),
    R("compare-channel-2d", "compare {rec_2d}", "RECORD", "'DE'", "(24000, 2)", "1-D"),
    R("compare-record-all-zero", "compare {rec_zero}", "RECORD", "constant", "sensor"),
    R("compare-channel-complex", "compare {rec_complex}", "RECORD", "'DE'", "complex values",
      "real samples"),
    R("compare-record-nan", "compare {rec_nan}", "RECORD", "3 non-finite samples",
      "sample 100"),
    R("compare-wav-header-rate", "compare {rec_wav_rate}", "RECORD", "48000 Hz",
      '"fs_hz" says 12000 Hz'),
    # ---- issue 28: recordings in the formats labs produce, what options state for them
    R("compare-fs-option-disagrees", "compare {record} --fs-hz 48000", "--fs-hz",
      '"fs_hz" says sample rate 12000 Hz', "48000 Hz"),
    # (--speed-rpm beside a documented speed is no longer bad input: it replaces it, with a
    # warning; issue 48, tests/unit/measured/test_stated_values.py)
    R("compare-unit-option-disagrees", "compare {rec_unit_g} --unit V", "--unit", "'g'",
      "'V'"),
    R("calibrate-fs-option-disagrees", "calibrate {record} --fs-hz 48000 --out "
      "{work}/m.toml", "--fs-hz", "12000 Hz", "48000 Hz"),
    R("spectrum-fs-option-disagrees", "spectrum {record} --fs-hz 48000", "--fs-hz",
      "12000 Hz", "48000 Hz"),
    R("spectrum-option-for-a-run", "spectrum {run} --speed-rpm 1000", "--speed-rpm",
      "cmsim wrote"),
    R("spectrum-rig-missing", "spectrum {record} --rig {work}/none.toml", "--rig"),
    R("compare-channel-not-in-mat", "compare {rec_mat} --channel X097_BA_time --fs-hz 12000",
      "--channel", "X097_DE_time", "X097_FE_time"),
    R("compare-mat-no-rig", "compare {rec_mat} --fs-hz 12000", "--rig", "geometry"),
    R("import-empty-dir", "import {empty_dir} --out {work}/m.json", "DIR",
      "no measured recording"),
    R("import-dir-missing", "import {work}/none", "DIR", "does not exist"),
    # ---- an output nothing can be written in is refused before the work, not after it
    R("simulate-out-unwritable", "simulate --speed-rpm 1000 --duration-s 0.01 --out "
      "/proc/cmsim-x.npz", "--out", "cannot write in /proc"),
    R("dataset-out-unwritable", "dataset {ds_spec} --out /proc/cmsim-ds", "--out",
      "cannot write in /proc"),
    R("spectrum-plot-unwritable", "spectrum {record} --plot /proc/cmsim-x.png", "--plot",
      "cannot write in /proc"),
    R("calibrate-out-unwritable", "calibrate {record} --out /proc/cmsim-m.toml", "--out",
      "cannot write in /proc"),
    R("import-out-exists", "import {measured_dir}", "--out", "exists", "--force",
      "its default"),
    R("import-fs-disagrees", "import {rec_wav_bare_dir} --out {work}/m.json --fs-hz 12000",
      "--fs-hz", "48000 Hz", "12000 Hz"),
    R("import-metadata-disagrees", "import {rec_wav_rate_dir} --out {work}/m.json", "DIR",
      "48000 Hz", 'metadata.json "fs_hz" says 12000 Hz'),
    R("import-channel-repeated", "import {measured_dir} --out {work}/m.json --channel DE DE",
      "--channel", "must not repeat", "DE DE"),
    R("calibrate-baseline-twice", "calibrate {record} {record} --out {work}/m.toml",
      "BASELINE", "given twice"),
    R("import-channel-missing", "import {measured_dir} --out {work}/m.json --channel FE",
      "--channel", "'FE'", "DE"),
    R("import-wav-names-count", "import {rec_wav_bare_dir} --out {work}/m.json --channel A B",
      "--channel", "1 unnamed signal", "2 names"),
    R("import-damaged", "import {rec_truncated_dir} --out {work}/m.json", "DIR",
      "truncated"),
    R("calibrate-record-truncated", "calibrate {rec_truncated} --out {work}/m.toml",
      "BASELINE", "truncated"),
    R("calibrate-metadata-fs-text", "calibrate {rec_fs_text} --out {work}/m.toml",
      "BASELINE", "fs_hz", "'12k'", numeric=True),
    R("calibrate-channel-2d", "calibrate {rec_2d} --out {work}/m.toml", "BASELINE", "'DE'",
      "1-D"),
    R("calibrate-record-all-zero", "calibrate {rec_zero} --out {work}/m.toml", "BASELINE",
      "constant"),
    R("calibrate-record-nan", "calibrate {rec_nan} --out {work}/m.toml", "BASELINE",
      "non-finite"),
    R("calibrate-wav-header-rate", "calibrate {rec_wav_rate} --out {work}/m.toml",
      "BASELINE", "48000 Hz"),
    R("spectrum-record-truncated", "spectrum {rec_truncated}", "RECORD", "truncated"),
    R("compare-text-renamed-npz", "compare {rec_text_npz}", "RECORD", "not an .npz (zip)"),
    R("spectrum-metadata-fs-text", "spectrum {rec_fs_text}", "RECORD", "fs_hz", "'12k'",
      numeric=True),
    R("spectrum-channel-2d", "spectrum {rec_2d}", "RECORD", "'DE'", "1-D"),
    R("spectrum-record-all-zero", "spectrum {rec_zero}", "RECORD", "constant"),
    R("spectrum-record-is-a-directory", "spectrum {measured_dir}", "RECORD",
      "is a directory"),
    R("simulate-rig-is-a-machine", "simulate --speed-rpm 1000 --rig {machine_other}", "--rig",
      "a machine file", "--machine"),
    R("spectrum-channel-complex", "spectrum {rec_complex}", "RECORD", "complex values"),
    R("calibrate-channel-complex", "calibrate {rec_complex} --out {work}/m.toml", "BASELINE",
      "complex values"),
    R("import-channel-complex", "import {rec_complex_dir} --out {work}/m.json", "DIR",
      "complex values"),
    R("spectrum-record-nan", "spectrum {rec_nan}", "RECORD", "non-finite"),
    R("spectrum-wav-header-rate", "spectrum {rec_wav_rate}", "RECORD", "48000 Hz"),
    R("spectrum-measured-signal", "spectrum {record} --channel nosuch", "--channel", "DE"),
    R("spectrum-old-signal-option", "spectrum {record} --signal nosuch", "--signal", "DE"),
    R("evaluate-measured-record-nan", "evaluate {rec_nan_dir} --algorithm envelope",
      "rec.npz", "non-finite"),
    R("evaluate-measured-fs-text", "evaluate {rec_fs_text_dir} --algorithm envelope",
      "metadata.json", "'12k'", numeric=True),
    # ---- h1 (issue 26): inputs at the edge — step vs excitation, faults files, duplicates,
    # ---- messages that name what the user typed
    R("simulate-substeps-under-resolve-mesh", "simulate --speed-rpm 100000 --torque-nm 50 "
      "--substeps 1 --duration-s 0.01", "--substeps", "GMF", "[18, 1000]", "--speed-rpm",
      numeric=True),
    R("simulate-fs-too-low-for-mesh", "simulate --speed-rpm 100000 --fs-hz 1000 "
      "--duration-s 0.01", "--fs-hz", ">= 1316", numeric=True),
    R("sweep-substeps-under-resolve-mesh", "sweep --speed-rpm 1000 100000 --substeps 1 "
      "--out {work}/s", "--substeps", "[18, 1000]", numeric=True),
    R("dataset-substeps-under-resolve-mesh", "dataset {ds_fast} --out {work}/d", "SPEC",
      "simulation.substeps", "[18, 1000]", numeric=True),
    R("simulate-faults-file-single-table", "simulate --speed-rpm 1000 --faults {faults_table}",
      "--faults", "[fault]", "[[faults]]"),
    R("simulate-faults-file-empty", "simulate --speed-rpm 1000 --faults {empty}", "--faults",
      "defines no fault"),
    R("simulate-faults-file-empty-list", "simulate --speed-rpm 1000 --faults {faults_none}",
      "--faults", "defines no fault"),
    R("simulate-faults-file-unknown-key", "simulate --speed-rpm 1000 --faults {faults_unknown}",
      "--faults", "'severity'"),
    R("sweep-faults-file-single-table", "sweep --speed-rpm 1000 --faults {faults_table} "
      "--out {work}/s", "--faults", "[fault]"),
    R("simulate-fault-repeated-key", "simulate --speed-rpm 1000 --fault "
      "outer_race:bearing=1b1,size_m=1e-3,size_m=2e-3,depth_m=1e-4", "--fault", "size_m",
      "twice"),
    R("simulate-fault-twice", "simulate --speed-rpm 1000 --fault "
      "outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4 --fault "
      "outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4", "--fault", "same fault"),
    R("simulate-two-cracks-one-tooth", "simulate --speed-rpm 1000 --fault "
      "tooth_crack:gear=1,depth_m=1e-3 --fault tooth_crack:gear=1,depth_m=5e-4", "--fault",
      "tooth 0 of gear 1"),
    R("simulate-eccentricity-option-and-file", "simulate --speed-rpm 1000 --faults "
      "{faults_ecc} --fault eccentricity:gear=1,amplitude_m=2e-5", "--fault", "--faults",
      "eccentricity of gear 1"),
    R("sweep-fault-twice", "sweep --speed-rpm 1000 --fault wear:bearing=1b1,"
      "clearance_growth_m=1e-5 --fault wear:bearing=1b1,clearance_growth_m=1e-5 "
      "--out {work}/s", "--fault", "same fault"),
    R("dataset-grid-repeated-value", "dataset {ds_grid_repeat} --out {work}/d", "SPEC",
      "operating.speed_rpm", "repeat"),
    R("report-only-failed-runs", "report {failed_sweep}", "DIR", "no finished runs",
      "1 failed", "T20000Nm"),
    R("simulate-torque-moves-centres", "simulate --speed-rpm 1000 --torque-nm 1e5 "
      "--duration-s 0.01", "--torque-nm", "gear centres", "<= about", numeric=True,
      needs_model=True),
    R("sweep-torque-moves-centres", "sweep --speed-rpm 1000 --torque-nm 10 1e5 "
      "--out {work}/s", "--torque-nm", "gear centres", "<= about", numeric=True,
      needs_model=True),
    R("simulate-torque-at-max-diverges", "simulate --speed-rpm 1000 --torque-nm 1e6 "
      "--duration-s 0.01", "--torque-nm", "no static equilibrium", "diverged", "cannot carry",
      "contact stress", status=3),
    R("simulate-sensor-fs-not-a-fraction", "simulate --speed-rpm 1000 --sensor-fs-hz 1234.567 "
      "--duration-s 0.01", "--sensor-fs-hz = 1234.57 Hz", "--fs-hz = 75000 Hz"),
    R("simulate-ramp-starts-after-record", "simulate --speed-rpm 1000 --ramp-to-rpm 2000 "
      "--ramp-start-s 5 --duration-s 0.01", "--ramp-start-s", "[0, 0.06)", numeric=True),
    R("modes-torque-zero", "modes --torque-nm 0", "--torque-nm", "> 0 N m", numeric=True),
    # ---- no command
    R("cmsim-no-command", "", "command"),
    R("cmsim-unknown-command", "frobnicate", "frobnicate"),
    R("cmsim-unknown-option", "modes --torque-nm 10 --frobnicate", "--frobnicate"),
]


def _numeric_options():
    """(command, option, dest) of every int/float option of every command."""
    parser = build_parser()
    out = []
    for command, sub in contract.subparsers(parser).items():
        for a in sub._actions:
            if a.option_strings and (a.type in (int, float) or hasattr(a.type, "allowed")):
                out.append((command, max(a.option_strings, key=len), a.dest, a.nargs))
    return out


def _generated_rows():
    rows = []
    for command, option, dest, nargs in _numeric_options():
        n = nargs if isinstance(nargs, int) else 1
        for bad in ("nan", "inf", "abc"):
            argv = f"{BASE[command]} {option} {' '.join([bad] * n)}"
            rows.append(R(f"{command}{option}-{bad}", argv, option, numeric=True))
    return rows


# ---- inclusive maxima (issue 26, tests that catch plausible bugs): every numeric option's
# documented maximum (the range its message states) is accepted, the next number above it
# refused; generated over all options of all commands, so an off-by-one at any upper bound
# (``>=`` for ``>``, a bound moved, a message that rounds it) fails.
def _documented_maximum(allowed):
    """``(text, closed)`` of the upper bound a range's text states (``"a number in [0, 0.3]"``
    -> ``("0.3", True)``), or None when it states none."""
    m = re.search(r" in [\[(][^,]+, ([^\])]+)([\])])", allowed)
    if m:
        return m.group(1), m.group(2) == "]"
    m = re.search(r" (<=?) (\S+)", allowed)
    return (m.group(2), m.group(1) == "<=") if m else None


def _just_above(text, integer):
    """The next value a user could type above ``text``: +1 for an integer, else the next
    float (exact, so ``>`` and ``>=`` differ)."""
    return str(int(text) + 1) if integer else repr(math.nextafter(float(text), math.inf))


def _maxima(closed_only=False):
    """(command, option, dest, nargs, allowed, maximum text, refused text) of every numeric
    option whose range has an upper bound; the refused text is the bound itself when the
    range excludes it, else the next value above it."""
    out = []
    for command, option, dest, nargs in _numeric_options():
        sub = contract.subparsers(build_parser())[command]
        allowed = next(a for a in sub._actions if a.dest == dest).type.allowed
        top = _documented_maximum(allowed)
        if top is None or (closed_only and not top[1]):
            continue
        text, closed = top
        above = _just_above(text, allowed.startswith("an integer")) if closed else text
        out.append((command, option, dest, nargs, allowed, text, above))
    return out


def _with_option(command, option, nargs, value):
    """BASE of ``command`` (without ``option`` if it gives it) plus ``option value``."""
    base = BASE[command].split()
    n = nargs if isinstance(nargs, int) else 1
    if option in base:
        i = base.index(option)
        del base[i: i + 1 + n]
    return base + [option] + [value] * n


def _above_maximum_rows():
    return [Row(f"{command}{option}-above-max", tuple(_with_option(command, option, nargs,
                                                                   above)),
                (option, allowed, above), 2, True)
            for command, option, _, nargs, allowed, _, above in _maxima()]


ALL_ROWS = CATALOGUE + _generated_rows() + _above_maximum_rows()


# ---------------------------------------------------------------------- fixtures
def _synthetic_run(rig, signals, fs=20_000.0, n=8192, meta_extra=None):
    t = np.arange(n) / fs
    rng = np.random.default_rng(0)
    sig = {name: np.sin(2 * np.pi * 466.67 * t) + 0.01 * rng.standard_normal(n)
           for name in signals}
    meta = {"rig": rig.to_dict(), "fs_hz": fs,
            "operating_point": {"speed_rpm": 1000.0, "torque_nm": 10.0, "radial_load_n": 0.0,
                                "radial_load_angle_rad": -math.pi / 2}, "seed": 0,
            **(meta_extra or {})}
    return Run(t, sig, meta)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Fixture files; ``work`` is the directory outputs would go to."""
    d = tmp_path_factory.mktemp("contract")
    f = {"work": d / "work", "tables": TABLES}
    f["work"].mkdir()
    (d / "text.txt").write_text("just some text\n")
    f["text"] = d / "text.txt"
    (d / "empty.toml").write_text("")
    f["empty"] = d / "empty.toml"
    (d / "empty_dir").mkdir()
    f["empty_dir"] = d / "empty_dir"
    paper = Rig.paper_2016()
    paper.save(d / "rig_ok.toml")
    f["rig_ok"] = d / "rig_ok.toml"
    bearing_rig = Rig.rotor_on_bearings(paper.bearings[0], cmsim.Rotor(3.0, 0.01))
    bearing_rig.save(d / "bearing_rig.toml")
    f["bearing_rig"] = d / "bearing_rig.toml"
    text = (d / "rig_ok.toml").read_text()

    def variant(name, old, new, nth=1):
        """The rig file with the ``nth`` occurrence of ``old`` replaced by ``new``."""
        i = -1
        for _ in range(nth):
            i = text.index(old, i + 1)
        (d / f"{name}.toml").write_text(text[:i] + new + text[i + len(old):])
        f[name] = d / f"{name}.toml"

    pair = "flexural_stiffness_n_per_m = [\n    624000000.0,\n    624000000.0,\n]"
    variant("rig_no_balls", "n_balls = 9\n", "")
    variant("rig_bool_mass", "mass_kg = 0.79999", "mass_kg = true")
    variant("rig_two_modules", "module_m = 0.003175\n", "module_m = 0.003175\nmodule_mm = 3.2\n")
    variant("rig_strings", pair, 'flexural_stiffness_n_per_m = ["a", "b"]', nth=2)
    variant("rig_stiff", "    624000000.0,", "    1e20,")
    variant("rig_teeth", "n_teeth = 28", "n_teeth = 100000", nth=2)
    variant("rig_nan", "clearance_m = 1.5e-05", "clearance_m = nan", nth=4)
    variant("rig_unknown", "module_m = ", "modul_m = ")
    (d / "rig_bad_faults.toml").write_text(text + '\n[[faults]]\ntype = "bogus"\n')
    f["rig_bad_faults"] = d / "rig_bad_faults.toml"
    (d / "faults_bad.toml").write_text(
        '[[faults]]\ntype = "ball"\nbearing = "1b1"\nsize_m = 5e-4\ndepth_m = 1e-4\n\n'
        '[[faults]]\ntype = "outer_race"\nbearing = "1b1"\nsize_m = -1e-3\ndepth_m = 1e-4\n')
    f["faults_bad"] = d / "faults_bad.toml"
    (d / "faults_gear.toml").write_text(
        '[[faults]]\ntype = "inner_race"\nbearing = "2b1"\nsize_m = 5e-4\ndepth_m = 1e-4\n')
    f["faults_gear"] = d / "faults_gear.toml"
    for name, text_ in (
            ("faults_table", '[fault]\ntype = "ball"\nbearing = "1b1"\nsize_m = 5e-4\n'
                             'depth_m = 1e-4\n'),
            ("faults_none", "faults = []\n"),
            ("faults_unknown", 'severity = 2\n[[faults]]\ntype = "wear"\nbearing = "1b1"\n'
                               'clearance_growth_m = 1e-5\n'),
            ("faults_ecc", '[[faults]]\ntype = "eccentricity"\ngear = 1\n'
                           'amplitude_m = 1e-5\n')):
        (d / f"{name}.toml").write_text(text_)
        f[name] = d / f"{name}.toml"
    ds_spec = ('[dataset]\nrecords = 2\n\n[sensor]\nchannels = ["accel_1b1_y"]\n'
               'duration_s = 0.01\n')
    ds_fast = ('[operating]\nsampling = "grid"\nspeed_rpm = [1000, 100000]\n\n[sensor]\n'
               'channels = ["accel_1b1_y"]\nduration_s = 0.01\n\n[simulation]\nsubsteps = 1\n')
    for name, text_ in (("ds_spec", ds_spec),
                        ("ds_zero", ds_spec.replace("records = 2", "records = 0")),
                        ("ds_fast", ds_fast),
                        ("ds_grid_repeat", ds_fast.replace("[1000, 100000]", "[1000, 1000.0]")
                         .replace("substeps = 1", "substeps = 3")),
                        ("ds_unknown_key", ds_spec.replace("channels", "chanels")),
                        ("ds_bad_fault", ds_spec + '\n[faults]\nhealthy_share = 0.5\n\n'
                                                   '[[faults.types]]\ntype = "bogus"\n')):
        (d / f"{name}.toml").write_text(text_)
        f[name] = d / f"{name}.toml"
    _generated_datasets(d, f)
    run = _synthetic_run(paper, ["F_1b1_loa", "F_1b1_oloa", "x_1b1", "y_1b1", "x_2b1", "y_2b1",
                                 "dte_um"])
    f["run"] = run.save(d / "run.npz")
    np.savez(d / "bad_meta.npz", t=run.t, meta="{not json", F_1b1_loa=run.t)
    f["bad_meta"] = d / "bad_meta.npz"
    np.savez(d / "bad_rig_meta.npz", t=run.t, meta=json.dumps({"rig": {"name": "x"}}),
             F_1b1_loa=run.t)
    f["bad_rig_meta"] = d / "bad_rig_meta.npz"
    sweep = d / "sweep"
    (sweep / "runs").mkdir(parents=True)
    run.save(sweep / "runs" / "r0.npz")
    f["sweep"] = sweep
    corrupt = d / "corrupt_sweep"
    (corrupt / "runs").mkdir(parents=True)
    raw = bytearray((sweep / "runs" / "r0.npz").read_bytes())
    raw[len(raw) // 2: len(raw) // 2 + 64] = b"\0" * 64
    (corrupt / "runs" / "r0.npz").write_bytes(bytes(raw))
    f["corrupt_sweep"] = corrupt
    failed = d / "failed_sweep"                    # a sweep whose one grid point failed
    (failed / "records").mkdir(parents=True)
    write_row(failed, {"index": 0, "record_id": "000_n1000rpm_T20000Nm", "status": "failed",
                       "speed_rpm": 1000.0, "torque_nm": 20000.0, "path": None,
                       "error": "IntegrationDiverged: the integration diverged"})
    f["failed_sweep"] = failed
    meas = d / "measured"                          # a measured record (cmsim compare)
    meas.mkdir()
    np.savez(meas / "rec.npz", DE=np.random.default_rng(0).standard_normal(24000))
    (meas / "metadata.json").write_text(json.dumps({
        "fs_hz": 12000.0, "sensors": {"DE": {"near": "de", "direction": "radial"}},
        "geometry": {"gears": None, "bearings": {"de": {
            "n_balls": 9, "ball_diameter_mm": 7.94, "pitch_diameter_mm": 39.04}}},
        "recordings": [{"file": "rec.npz", "shaft_speed_rpm": 1797.0}]}))
    f["record"] = meas / "rec.npz"
    f["measured_dir"] = meas
    grid = tuple(np.linspace(0.0, 6000.0, 9))          # a machine of another rig's channel
    Machine(name="other", rig=paper, channel="a1", model_signal="accel_1b1_y", fs_hz=12000.0,
            op=cmsim.OperatingPoint(1797.0, 10.0),
            path=TransferPath("F_1b1_y", grid, (0.01,) * len(grid), "g"),
            background=Background(grid, (1e-12,) * len(grid)), unit="g").save(d / "other.toml")
    f["machine_other"] = d / "other.toml"
    cmsim.rig.preset("cwru_6205").save(d / "rig_cwru.toml")     # not the machine's rig
    f["rig_cwru"] = d / "rig_cwru.toml"
    mat = d / "mat"                                # a CWRU-layout .mat, no metadata.json
    mat.mkdir()
    from scipy.io import savemat
    x = np.random.default_rng(2).standard_normal((24000, 1))
    savemat(mat / "rec.mat", {"X097_DE_time": x, "X097_FE_time": x, "X097RPM": 1797.0})
    f["rec_mat"] = mat / "rec.mat"
    f.update(_bad_recordings(d / "bad_recordings"))
    f["root"] = d
    return f


ALGORITHMS = """import os
import sys


def boom(signals, fs_hz, operating_point, frequencies):
    raise ValueError("nope")


def leave(signals, fs_hz, operating_point, frequencies):
    sys.exit(1)


CALLS = []


def chatty(signals, fs_hz, operating_point, frequencies):
    # prints, writes to file descriptor 1, and fails on its first record only
    CALLS.append(1)
    print("chatty print")
    os.write(1, b"chatty fd 1\\n")
    if len(CALLS) == 1:
        raise ValueError("first record")
    return "healthy"
"""


def _generated_datasets(d, f):
    """A dataset generated from ``ds_spec`` and copies of it broken in one way each: every
    record truncated, every record deleted, the manifest cut short, a foreign Parquet file
    as the manifest; and the users' algorithms (issue 26)."""
    import shutil

    import pandas as pd

    from cmsim.datasets import DatasetSpec, generate_dataset

    gen = d / "gen"
    generate_dataset(DatasetSpec.load(f["ds_spec"]), gen, workers=1, progress=False)
    f["gen_ds"] = gen
    for name in ("gen_truncated", "gen_deleted", "gen_bad_manifest", "gen_foreign_manifest"):
        shutil.copytree(gen, d / name)
        f[name] = d / name
    for rec in (d / "gen_truncated" / "records").glob("*.npz"):
        rec.write_bytes(rec.read_bytes()[:1000])
    for rec in (d / "gen_deleted" / "records").glob("*.npz"):
        rec.unlink()
    manifest = d / "gen_bad_manifest" / "manifest.parquet"
    manifest.write_bytes(manifest.read_bytes()[:300])
    pd.DataFrame({"x": [1.0]}).to_parquet(d / "gen_foreign_manifest" / "manifest.parquet")
    (d / "algo.py").write_text(ALGORITHMS)
    f["algo"] = d / "algo.py"
    (d / "algo_exit.py").write_text("import sys\nsys.exit(3)\n")
    f["algo_exit"] = d / "algo_exit.py"


def _measured_folder(folder, arrays, *, fs_hz=12000.0, file="rec.npz", entry=None,
                     sensors_unit=None):
    """A folder with one recording (``arrays``: channel -> samples, or bytes: the raw file)
    and its metadata.json (a CWRU-like bearing rig, sensor DE near the drive end)."""
    folder.mkdir(parents=True)
    if isinstance(arrays, bytes):
        (folder / file).write_bytes(arrays)
    elif arrays is not None:
        np.savez(folder / file, **arrays)
    (folder / "metadata.json").write_text(json.dumps({
        "fs_hz": fs_hz, "sensors": {"DE": {"near": "de", "direction": "radial",
                                           "unit": sensors_unit},
                                    "FE": {"near": "fe", "direction": "radial"}},
        "geometry": {"gears": None, "bearings": {
            "de": {"n_balls": 9, "ball_diameter_mm": 7.94, "pitch_diameter_mm": 39.04},
            "fe": {"n_balls": 8, "ball_diameter_mm": 6.75, "pitch_diameter_mm": 28.5}}},
        "recordings": [{"file": file, "shaft_speed_rpm": 1797.0, **(entry or {})}]}))
    return folder / file


def _bad_recordings(d):
    """Measured recordings damaged in each way a user's file can be (issue 26): truncated,
    a numeric metadata value written as text, a 2-D channel, a complex channel (a spectrum
    stored where a time history belongs), all zero, a few NaN, a WAV whose header rate
    contradicts metadata.json."""
    x = np.random.default_rng(1).standard_normal(24000)
    ok = _measured_folder(d / "ok", {"DE": x, "FE": x})
    raw = ok.read_bytes()
    with_nan = x.copy()
    with_nan[[100, 9000, 20000]] = np.nan
    f = {"rec_truncated": _measured_folder(d / "truncated", raw[: len(raw) // 2]),
         "rec_text_npz": _measured_folder(d / "text_npz", b"time,acc\n0,1\n"),
         "rec_fs_text": _measured_folder(d / "fs_text", {"DE": x}, entry={"fs_hz": "12k"}),
         "rec_2d": _measured_folder(d / "two_d", {"DE": np.stack([x, x], 1), "FE": x}),
         "rec_zero": _measured_folder(d / "zero", {"DE": np.zeros_like(x)}),
         "rec_complex": _measured_folder(d / "complex", {"DE": (x + 1j * x).astype(np.complex64)}),
         "rec_nan": _measured_folder(d / "nan", {"DE": with_nan}),
         "rec_unit_g": _measured_folder(d / "unit_g", {"DE": x}, sensors_unit="g")}
    wav = _measured_folder(d / "wav", None, file="rec.wav", entry={"channels": ["DE"]})
    with wave.open(str(wav), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(48000)
        w.writeframes((x / np.abs(x).max() * 30000).astype("<i2").tobytes())
    f["rec_wav_rate"] = wav
    bare = d / "wav_bare"                    # the same WAV without metadata.json
    bare.mkdir()
    (bare / "rec.wav").write_bytes(wav.read_bytes())
    f["rec_wav_bare"] = bare / "rec.wav"
    f.update({f"{k}_dir": v.parent for k, v in list(f.items())})
    return f


def _argv(row, files):
    return [a.format(**{k: str(v) for k, v in files.items()}) for a in row.argv]


def _tree(root):
    return sorted(str(p.relative_to(root)) for p in Path(root).rglob("*"))


def _check_message(row, line):
    assert "Traceback" not in line
    assert line.startswith("cmsim"), line
    for word in row.names:
        assert word in line, f"{word!r} not in {line!r}"
    assert "np.float64" not in line and "inf]" not in line and "-inf" not in line, line
    if row.numeric:
        assert any(s in line for s in (" in [", " in (", ">", "<", "one of", "allowed")), line


def _error_line(row, err):
    """The one error line of ``err``. Bad input (exit 2) is refused before any heavy step, so
    it is the only line, unless its bound is the model's (``needs_model``); a run that
    started and diverged (exit 3) may follow the progress notice of the numba compile
    (``cmsim: ...``, never an error), which a cold cache prints before the run: the rule
    counts the error line, not the cache's state."""
    lines = err.strip().splitlines()
    assert lines, err
    before = lines[:-1]
    if row.status == 3 or row.needs_model:
        assert all(line.startswith("cmsim: ") and "error" not in line for line in before), err
    else:
        assert not before, err
    return lines[-1]


@pytest.fixture
def cold_numba_cache(monkeypatch):
    """Every command sees a cold numba cache (as on a fresh install or with an empty
    ``NUMBA_CACHE_DIR``): the compile notice is printed wherever a command reaches it."""
    from cmsim.dynamics import simulation
    monkeypatch.setattr(simulation, "kernels_cached", lambda: False)


# ---------------------------------------------------------------------- tests
@pytest.mark.parametrize("row", ALL_ROWS, ids=[r.id for r in ALL_ROWS])
@pytest.mark.parametrize("as_json", [False, True], ids=["text", "json"])
def test_bad_input(row, as_json, files, capsys, cold_numba_cache):
    before = _tree(files["root"])
    argv = _argv(row, files) + (["--json"] if as_json else [])
    status = main(argv)
    cap = capsys.readouterr()
    assert status == row.status, cap.err
    line = _error_line(row, cap.err)
    _check_message(row, line)
    if as_json:
        obj = json.loads(cap.out)
        assert isinstance(obj, dict) and obj["status"] == row.status
        assert obj["error"] in line
        if row.argv and row.argv[0] in BASE:        # issue 26: never "option": null
            assert obj["option"] and obj["option"] in obj["error"], obj
    else:
        assert cap.out == ""
    assert _tree(files["root"]) == before


def test_calibrate_never_writes_over_a_baseline_found_under_cmsim_data(files, tmp_path,
                                                                       monkeypatch, capsys):
    """--out is refused when it is a BASELINE however the BASELINE was found: as typed, or
    (a relative path) under $CMSIM_DATA — with --force too (a user's data overwritten by
    the machine file before the fix)."""
    root = tmp_path / "data"
    (root / "rig").mkdir(parents=True)
    for name in ("rec.npz", "metadata.json"):
        (root / "rig" / name).write_bytes((files["measured_dir"] / name).read_bytes())
    before = (root / "rig" / "rec.npz").read_bytes()
    monkeypatch.setenv("CMSIM_DATA", str(root))
    monkeypatch.chdir(tmp_path)
    status = main(["calibrate", "rig/rec.npz", "--out", str(root / "rig" / "rec.npz"),
                   "--force", "--json"])
    cap = capsys.readouterr()
    assert status == 2 and json.loads(cap.out)["option"] == "--out", cap.err
    assert "BASELINE" in cap.err and (root / "rig" / "rec.npz").read_bytes() == before


def test_simulate_through_a_machine_runs_at_its_operating_point(files, tmp_path, capsys):
    """simulate --machine without --speed-rpm / --torque-nm / --radial-load-n runs at the
    machine's speed and load; an option given still wins; without a machine the speed is
    required."""
    out = tmp_path / "run.npz"
    assert main(["simulate", "--machine", str(files["machine_other"]), "--duration-s", "0.02",
                 "--out", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["shaft_hz"] == pytest.approx(1797.0 / 60.0)
    meta = Run.load(out).meta["operating_point"]
    assert (meta["speed_rpm"], meta["torque_nm"]) == (1797.0, 10.0)
    assert res["mesh_table"]["method"] == "potential-energy"     # the twin's tooth contact
    assert main(["simulate", "--machine", str(files["machine_other"]), "--duration-s", "0.02",
                 "--torque-nm", "20", "--out", str(out), "--json"]) == 0
    capsys.readouterr()
    assert Run.load(out).meta["operating_point"]["torque_nm"] == 20.0


def test_catalogue_size_and_commands():
    """Every command `cmsim --help` lists has rows, and the catalogue has ~60+ hand rows."""
    commands = set(contract.subparsers(build_parser()))
    assert commands == set(BASE)
    covered = {r.argv[0] for r in CATALOGUE if r.argv}
    assert commands <= covered
    assert len(CATALOGUE) >= 60


def test_every_option_is_validated():
    """Each numeric option has a range (parse time) or is checked by the library under a name
    that maps to it; each other option has choices, is a path, a flag, or a name checked
    against the run."""
    parser = build_parser()
    # checked against the run's signals / bearings; --fault by cmsim.faults.parse_fault
    # --algorithm: load_algorithm; --scheduler: checked by connecting (names --scheduler)
    # compare's RECORD and calibrate's BASELINE may be relative to $CMSIM_DATA: the library
    # checks them (and the command names them)
    # export's RUN|DATASET is a file or a folder, its --channels are checked against the
    # source, --group-by against the manifest
    free_text = {"signal", "bearing", "fault", "algorithm", "scheduler", "record", "channel",
                 "baseline", "source", "channels", "group_by", "unit", "signal_alias"}
    for command, sub in contract.subparsers(parser).items():
        for a in sub._actions:
            if isinstance(a, (argparse._HelpAction, argparse._StoreTrueAction)):
                continue
            if a.type in (int, float):
                raise AssertionError(f"{command} {a.dest}: a number without a range")
            elif hasattr(a.type, "allowed"):
                continue
            else:
                assert (a.choices is not None or a.dest in free_text
                        or (command, a.dest) in contract.PATHS or a.dest in contract.PATHS), \
                    (command, a.dest)


@pytest.mark.parametrize("command, option, dest, nargs, allowed, top, above",
                         _maxima(closed_only=True),
                         ids=[f"{c}{o}" for c, o, *_ in _maxima(closed_only=True)])
def test_documented_maximum_is_accepted(command, option, dest, nargs, allowed, top, above):
    """The maximum an option's range states parses to itself (parse only: no command runs);
    its refusal just above is a row of ALL_ROWS (``<command><option>-above-max``)."""
    argv = app._plain_negative_numbers(_with_option(command, option, nargs, top))
    value = getattr(build_parser().parse_args(argv), dest)
    values = value if isinstance(value, list) else [value]
    assert values and all(v == pytest.approx(float(top), rel=1e-15) for v in values), allowed


def test_param_names_map_to_options():
    """A ParameterError naming a Python field reads as the option typed."""
    from cmsim.errors import ParameterError, check_range
    options = contract.options_of(build_parser(), "spectrum")
    try:
        check_range("max_peaks", 0, 1, 100)
    except ParameterError as exc:
        msg, option = contract.user_message(exc, options)
    assert option == "--top" and msg.startswith("--top must be") and "max_peaks" not in msg
    options = contract.options_of(build_parser(), "simulate")
    for param, opt in (("cage_speed_rms", "--cage-slip"), ("torque_nm", "--torque-nm"),
                       ("clearance_m", "--clearance-m")):
        msg, option = contract.user_message(ParameterError(f"{param} must be >= 0, got -1"), options)
        assert option == opt and msg.startswith(opt)
    msg, _ = contract.user_message(ParameterError("n_positions must be an integer >= 4"),
                               contract.options_of(build_parser(), "modes"))
    assert msg.startswith("--positions")
    # a name that is part of a path stays as typed (export --out /tmp/out)
    msg, option = contract.user_message(
        ParameterError("out /tmp/out/x/out: exists", param="out"),
        contract.options_of(build_parser(), "export"))
    assert option == "--out" and msg == "--out /tmp/out/x/out: exists"


def test_internal_error_is_one_line_status_1(capsys, monkeypatch):
    def boom(args):
        raise ZeroDivisionError("x")

    parser = app.build_parser

    def patched():
        p = parser()
        contract.subparsers(p)["modes"].set_defaults(func=boom)
        return p

    monkeypatch.setattr(app, "build_parser", patched)
    assert main(["modes", "--torque-nm", "10", "--json"]) == 1
    cap = capsys.readouterr()
    assert len(cap.err.strip().splitlines()) == 1 and "please report" in cap.err
    assert json.loads(cap.out)["status"] == 1


def test_report_bearing_rig_without_dte(files, tmp_path, capsys):
    """report works on a bearing rig's sweep: the default signals skip dte_um."""
    bearing_rig = Rig.load(files["bearing_rig"])
    run = _synthetic_run(bearing_rig, ["F_1b1_loa", "F_1b1_oloa", "x_1b1", "y_1b1"])
    (tmp_path / "runs").mkdir()
    run.save(tmp_path / "runs" / "r0.npz")
    assert main(["report", str(tmp_path), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert Path(res["html"]).is_file()


def test_plausibility_warning_text_and_json(capsys):
    """1000 N m on the paper's 6.35 mm face: one warning naming --torque-nm, on stderr as
    text (after the result), in the JSON object's "warnings" with --json and then nothing on
    stderr; 100 N m: no warning. (The library gives the warning: load_warnings.)"""
    argv = ["modes", "--torque-nm", "1000", "--positions", "4"]
    assert main(argv) == 0
    cap = capsys.readouterr()
    warned = [line for line in cap.err.splitlines() if "warning" in line]
    assert len(warned) == 1 and "--torque-nm 1000" in warned[0] and "MPa" in warned[0]
    assert "torque_nm" not in cap.err
    assert main(argv + ["--json"]) == 0
    cap = capsys.readouterr()
    res = json.loads(cap.out)
    assert len(res["warnings"]) == 1 and res["warnings"][0].startswith("--torque-nm 1000")
    assert cap.err == ""
    assert main(["modes", "--torque-nm", "100", "--positions", "4", "--json"]) == 0
    cap = capsys.readouterr()
    assert "warnings" not in json.loads(cap.out) and cap.err == ""


@pytest.mark.parametrize("argv, status, word", [
    (["simulate", "--speed-rpm", "nan"], 2, "--speed-rpm"),
    (["spectrum", "/"], 2, "RECORD"),
    (["modes", "--torque-nm", "10", "--positions", "2"], 2, "--positions"),
    (["frobnicate"], 2, "frobnicate"),
    (["sweep", "--speed-rpm", "1000", "--out", "/etc/hostname"], 2, "--out"),
])
@pytest.mark.parametrize("as_json", [False, True], ids=["text", "json"])
def test_subprocess_exit_codes(argv, status, word, as_json):
    """The real process: exit code, one stderr line, nothing else on stdout."""
    cmd = [sys.executable, "-m", "cmsim.cli", *argv] + (["--json"] if as_json else [])
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert proc.returncode == status
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and word in lines[0] and "Traceback" not in proc.stderr
    if as_json:
        assert json.loads(proc.stdout)["status"] == status
    else:
        assert proc.stdout == ""


# ---------------------------------------------------------------------- user code, files
# (issue 26): the rows above cover the failures; these the runs that go on.
def test_evaluate_stdout_is_one_json_object_whatever_the_algorithm_prints(files, tmp_path):
    """The real process: the algorithm's print and its writes to descriptor 1 reach stderr;
    its error on one record is that record's, with the traceback, in the JSON and the
    HTML report; the other record is scored (exit 0)."""
    html = tmp_path / "eval.html"
    cmd = [sys.executable, "-m", "cmsim.cli", "evaluate", str(files["gen_ds"]), "--algorithm",
           f"{files['algo']}:chatty", "--report", str(html), "--json"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    res = json.loads(proc.stdout)
    assert "chatty print" in proc.stderr and "chatty fd 1" in proc.stderr
    assert (res["metrics"]["n_scored"], res["metrics"]["n_failed"]) == (1, 1)
    failed = [r for r in res["records"] if r["error"]]
    assert failed[0]["error"] == "ValueError: first record"
    assert "in chatty" in failed[0]["traceback"]
    page = html.read_text()
    assert "<details><summary>traceback</summary>" in page and "in chatty" in page


@pytest.mark.parametrize("damage", ["truncated", "deleted"])
def test_evaluate_skips_a_damaged_record_and_counts_it(damage, files, tmp_path, capsys):
    import shutil

    ds = tmp_path / "ds"
    shutil.copytree(files["gen_ds"], ds)
    victim = sorted((ds / "records").glob("*.npz"))[0]
    if damage == "truncated":
        victim.write_bytes(victim.read_bytes()[:1000])
    else:
        victim.unlink()
    assert main(["evaluate", str(ds), "--algorithm", "envelope", "--json"]) == 0
    cap = capsys.readouterr()
    res = json.loads(cap.out)
    m = res["metrics"]
    assert (m["n_records"], m["n_scored"], m["records_unreadable"]) == (1, 1, 1)
    assert list(res["unreadable"]) == [victim.stem]
    assert len(res["warnings"]) == 1 and victim.stem in res["warnings"][0]
    assert main(["evaluate", str(ds), "--algorithm", "envelope"]) == 0
    cap = capsys.readouterr()
    assert f"record {victim.stem} skipped" in cap.out
    assert len(cap.err.strip().splitlines()) == 1 and "warning" in cap.err


@pytest.mark.parametrize("damage", ["truncated", "deleted"])
def test_evaluate_skips_a_damaged_measured_recording(damage, tmp_path, capsys):
    """A folder of measured recordings with one damaged: the others are scored (exit 0),
    the damaged one is named in a warning and counted; sim-to-real's test windows leave it
    out too, naming it (one record never stops a batch: issue 48)."""
    import shutil

    from cmsim.measured import data_root

    source = data_root() / "mfpt_bearing"
    if not (source / "metadata.json").is_file():
        pytest.skip(f"measured data not found at {source} (set CMSIM_DATA)")
    folder = tmp_path / "mfpt"
    shutil.copytree(source, folder)
    victim = folder / "OR_vload3_100lb.npz"
    if damage == "truncated":
        victim.write_bytes(victim.read_bytes()[:5000])
    else:
        victim.unlink()
    assert main(["evaluate", str(folder), "--algorithm", "envelope", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    m = res["metrics"]
    assert (m["n_records"], m["n_scored"], m["records_unreadable"]) == (6, 6, 1)
    assert list(res["unreadable"]) == ["OR_vload3_100lb"]
    skipped = [w for w in res["warnings"] if "could not be read" in w]   # (IR_vload1_0lb's
    assert len(skipped) == 1 and "OR_vload3_100lb" in skipped[0]         # lines warn too)
    from cmsim.diagnostics.syn2real import measured_windows
    test = measured_windows(folder, max_windows=2)
    assert list(test.skipped) == ["OR_vload3_100lb"] and len(set(test.groups)) == 6


def test_calibrate_warns_when_its_baseline_departs_from_itself():
    """A baseline whose odd segments depart from its even ones as compare judges a record
    (the same σ and χ², discrepancy.judge.baseline_consistency) is said so, naming the worst
    feature; a stationary one is not."""
    from types import SimpleNamespace

    from cmsim.cli.calibrate import _warn_consistency
    said = []
    args = SimpleNamespace(warn=said.append)
    _warn_consistency(args, {"chi2_per_feature": 6.07, "worst_feature": "kurtosis_log",
                             "worst_z": -12.1, "departs": True})
    assert len(said) == 1 and "6.07" in said[0] and "kurtosis_log z -12.1" in said[0]
    _warn_consistency(args, {"chi2_per_feature": 1.16, "worst_feature": "shape_b2_db",
                             "worst_z": 2.4, "departs": False})
    assert len(said) == 1


def test_a_recording_without_geometry_is_read_on_the_machine_s_rig(tmp_path, capsys):
    """compare --machine of a recording with no geometry (no metadata.json, no --rig) reads
    it on the machine's rig (issue 48: it was told to give --rig although the machine holds
    its rig), and the record's unit, stated by --unit, is applied against the machine's."""
    from cmsim.discrepancy.signatures import build_library
    from cmsim.discrepancy.synthetic import hidden_effect_record
    from cmsim.machine import calibrate
    base = hidden_effect_record(None, 1003, duration_s=2.0, sim_seed=9).record
    m = calibrate([base], seed=1)
    m.with_library(build_library(m, causes=[], seed=1)).save(tmp_path / "m.toml")
    rec = hidden_effect_record(None, 1003, duration_s=2.0, sim_seed=11).record
    np.savez(tmp_path / "rec.npz", DE=(rec.signal / 9.80665).astype(np.float32))
    status = main(["compare", str(tmp_path / "rec.npz"), "--machine", str(tmp_path / "m.toml"),
                   "--fs-hz", "12000", "--speed-rpm", "1797", "--channel", "DE",
                   "--unit", "g", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert status == 0, out
    assert out["finding"] == "none", out["discrepancies"][:3]   # the level in g is applied


def test_a_model_warning_is_one_line_of_the_command_not_python_s(capsys, monkeypatch):
    """A formula used beyond its fit (Sainsot's fillet foundation on an unusual tooth) is
    said as the command's one-line warning, never as Python's warning with a source path
    (issue 48: a library UserWarning leaked from calibrate)."""
    import warnings as w

    from cmsim.errors import ModelWarning

    def func(args):
        w.warn("Sainsot fillet-foundation formula extrapolated (θf = 0.1 rad)", ModelWarning)
        w.warn("Sainsot fillet-foundation formula extrapolated (θf = 0.1 rad)", ModelWarning)
        return {}

    said = []
    args = types.SimpleNamespace(func=func, warn=said.append)
    app._run_warned(args)
    assert said == ["Sainsot fillet-foundation formula extrapolated (θf = 0.1 rad)"]
    assert "potential_energy.py" not in capsys.readouterr().err


def test_a_warning_raised_in_a_loop_is_passed_on_once():
    """A warning the library raises once per sample (numpy's, say) reaches the user once per
    text and place: passing on each of them made a command look hung for minutes after its
    work was done (a complex recording warned at every cast)."""
    import warnings as w

    def func(args):
        for _ in range(20_000):
            w.warn("casting discards something", RuntimeWarning)
        return {}

    args = types.SimpleNamespace(func=func, warn=lambda text: None)
    with w.catch_warnings(record=True) as passed:
        w.simplefilter("always")
        app._run_warned(args)
    assert [str(x.message) for x in passed] == ["casting discards something"]
