"""A record and its machine at one sample rate (:func:`cmsim.discrepancy.compare` with a
machine): a record sampled faster than the machine's baseline is read at the machine's rate;
against one sampled slower, the machine is calibrated again on its kept baseline resampled
to the record's rate. Both through :func:`cmsim.sensors.decimate` (the one resampler), both
said in the comparison's notes; a rate neither resamples to is refused.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from cmsim.discrepancy.causes import CAUSES
from cmsim.discrepancy.signatures import DENSER, GRIDS, N_SIZES, build_library
from cmsim.errors import ParameterError
from cmsim.machine import calibrate
from cmsim.measured import record_from_run
from cmsim.run import Run
from cmsim.sensors import MAX_RATIO_DENOMINATOR, sensor_rate_ratio

__all__ = ["check_machine", "machine_at_rate"]


def check_machine(record, machine, workers=1):
    """The machine must be the record's: same channel and bearings, and its sample rate. A
    record sampled faster is read at the machine's rate (resampled); against a record sampled
    slower, whose bands the machine's features overreach, the machine is calibrated again on
    its own kept baseline resampled to the record's rate (:func:`machine_at_rate`). Either is
    said in the notes.

    Parameters
    ----------
    record : MeasuredRecord
        The record compared.
    machine : cmsim.machine.Machine
        Its machine.
    workers : int
        Processes that build the library of a machine calibrated again.

    Returns
    -------
    (MeasuredRecord, Machine, list of str)
        The record and the machine as compared, and the notes on a resampling.
    """
    if machine.channel != record.channel:
        raise ParameterError(f"the machine was calibrated on channel {machine.channel!r}, the "
                             f"record's is {record.channel!r}", param="machine")
    if machine.rig.bearing_names != record.rig.bearing_names or (
            (machine.rig.gears is None) != (record.rig.gears is None)):
        raise ParameterError("the machine's rig is not the record's (other bearings or "
                             "gears)", param="machine")
    if abs(machine.fs_hz / record.fs_hz - 1.0) <= 0.01:
        return record, machine, []
    rates = (f"the machine was calibrated at {machine.fs_hz:g} Hz, the record is at "
             f"{record.fs_hz:g} Hz")
    try:
        sensor_rate_ratio(max(machine.fs_hz, record.fs_hz), min(machine.fs_hz, record.fs_hz))
    except ParameterError:
        raise ParameterError(f"{rates}, and neither can be resampled to the other (their "
                             f"ratio is no fraction up/down with down <= "
                             f"{MAX_RATIO_DENOMINATOR}); give the record at the machine's rate",
                             param="machine") from None
    if record.fs_hz > machine.fs_hz:
        note = f"{rates}: the record was low-passed and resampled to the machine's rate"
        return record.resampled(machine.fs_hz), machine, [note]
    t0 = time.perf_counter()
    key = (id(machine), round(record.fs_hz, 6))
    kept = _AT_RATE.get(key)
    if kept is None or kept[0] is not machine:
        if len(_AT_RATE) >= 4:
            _AT_RATE.pop(next(iter(_AT_RATE)))
        kept = _AT_RATE[key] = (machine, machine_at_rate(machine, record, workers))
    note = (f"{rates}: the machine was calibrated again on its kept baseline, low-passed and "
            f"resampled to the record's rate ({time.perf_counter() - t0:.0f} s, once a "
            f"process; cmsim calibrate --resample-hz {record.fs_hz:g} keeps such a machine)")
    return record, kept[1], [note]


#: Machines calibrated again at a record's rate in this process: (id of the machine, rate)
#: → (the machine, the one at that rate).
_AT_RATE = {}


def machine_at_rate(machine, record, workers=1):
    """The machine calibrated again on its kept baseline, resampled to ``record``'s lower
    sample rate (its operating point, channel, unit and the loads it assumed; the record's
    model rig), with a signature library of the causes, sizes and seed of its own.

    Parameters
    ----------
    machine : cmsim.machine.Machine
        With its baseline's samples (a version-2 machine file or later).
    record : MeasuredRecord
        The record compared (its rate, a fraction of the machine's, and its model rig).
    workers : int
        Processes that build the library.

    Returns
    -------
    cmsim.machine.Machine
    """
    if machine.baseline is None:
        raise ParameterError("the machine file keeps no baseline samples to calibrate again "
                             "from", param="machine")
    fs = machine.baseline.fs_hz
    base = [record_from_run(Run(np.arange(x.size) / fs, {machine.channel: np.asarray(x, float)},
                                {"fs_hz": fs}, source="measured"), machine.channel,
                            record.rig, machine.op, model_signal=machine.model_signal,
                            components=dict(machine.components),
                            unit_scale=machine.unit_scale).resampled(record.fs_hz)
            for x in machine.baseline.records]
    lib = machine.library
    again = calibrate(base, seg_s=machine.segment_s, seed=lib.seed if lib else 0,
                      name=machine.name)
    again = replace(again, assumed_load=machine.assumed_load)
    if lib is None:
        return again
    causes = list(dict.fromkeys(e.cause for e in lib.entries))
    n_sizes = lib.n_sizes
    if n_sizes is None:           # a file from before the library kept it: its grids' mode
        plain = [len(e.values) for e in lib.entries
                 if e.cause not in GRIDS and e.cause not in DENSER]
        n_sizes = max(set(plain), key=plain.count) if plain else N_SIZES
    return again.with_library(build_library(
        again, causes=[CAUSES[c]() for c in causes], seed=lib.seed, workers=workers,
        n_segments=lib.segments, n_sizes=n_sizes))
