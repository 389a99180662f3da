"""The load a record is read at against its machine, and the machine's library moved to it
(issue 16: a record documented at another load than its baseline's is read against the
baseline moved by the model's change between the two loads, each feature within that
change's own size; :mod:`cmsim.discrepancy.judge` step 2).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from cmsim.discrepancy.signatures import operating_shift
from cmsim.measured.schema import RADIAL_KEYS, TORQUE_KEYS, undocumented_load

__all__ = ["record_load", "at_operating_point", "LOAD_TOLERANCE",
           "OPERATING_SHIFT_UNCERTAINTY", "TORQUE_KEYS", "RADIAL_KEYS"]

#: A record's documented load (torque, radial load) differing from the machine's by more than
#: this share moves the baseline by the model's change between them
#: (:func:`~cmsim.discrepancy.signatures.operating_shift`).
LOAD_TOLERANCE = 0.1


#: The model's change of a feature between the machine's load and a record's is read to
#: within this share of itself (added in quadrature to the model's realisation spread). A
#: gearbox's own load response is not the model's: SpectraQuest's healthy record at 50 %
#: load sits on its 0 % baseline where the model moves the mesh sidebands 19 dB and the
#: broadband 11 dB, so a shift taken as exact named a tooth fault on a healthy record; the
#: CWRU records across loads (0 → 1 hp) move their defect families far beyond their shift.
OPERATING_SHIFT_UNCERTAINTY = 1.0


def record_load(record, machine):
    """(operating point, note): the load a record is read at against its machine — the
    record's documented torque and radial load, and the machine's own where the record's
    metadata documents none (reading a file, the model assumes a load it does not know:
    20 N m on a gear rig; against a machine, the baseline's load is the best guess, and a
    shift to an assumed load moved a 50-N m gear machine's whole baseline and named a ball
    defect for its tooth fault). A load the machine's baseline did not document either
    (:attr:`~cmsim.machine.Machine.assumed_load`) is the model's assumption, not a
    measurement: a record's documented load is not compared with it, and the record is read
    at the machine's. An in-memory record (a run) carries its own load.

    Parameters
    ----------
    record : MeasuredRecord
    machine : cmsim.machine.Machine

    Returns
    -------
    (cmsim.rig.OperatingPoint, str)
        The note says what was taken from the machine ("" when nothing was).
    """
    op = record.op
    if not record.path:
        return op, ""
    undocumented = undocumented_load(record.meta.get("recording"))
    taken, unknown = [], []
    for field, gears, what in (
            ("torque_nm", True, f"torque {machine.op.torque_nm:g} N m"),
            ("radial_load_n", False, f"radial load {machine.op.radial_load_n:g} N")):
        if gears and (record.rig is None or record.rig.gears is None):
            continue
        if getattr(op, field) == getattr(machine.op, field):
            continue
        if field in undocumented:
            taken.append(what)
        elif field in machine.assumed_load:
            unknown.append(what)
        else:
            continue
        op = replace(op, **{field: getattr(machine.op, field)})
    notes = []
    if taken:
        notes.append("the record documents no load: read at the machine's ("
                     + ", ".join(taken) + ")")
    if unknown:
        notes.append("the machine's baseline documented no load (its "
                     + ", ".join(unknown) + " was assumed at calibration): the record's "
                     "documented load is not compared with it, and the record is read at the "
                     "machine's")
    return op, "; ".join(notes)


def at_operating_point(machine, lib, op, *, threads=1):
    """(library, note): the library with every reference and prediction moved by the model's
    change from the machine's documented load to the record's, where they differ by more than
    :data:`LOAD_TOLERANCE` (the baseline at 0 % load, a record at 50 %), each feature's
    run-to-run spreads widened by that change's own size
    (:data:`OPERATING_SHIFT_UNCERTAINTY`); else as it is.

    Parameters
    ----------
    machine : cmsim.machine.Machine
    lib : SignatureLibrary
        Its library.
    op : cmsim.rig.OperatingPoint
        The record's (:func:`record_load`).
    threads : int
        Threads of the model's two runs (:func:`~cmsim.discrepancy.signatures.change_of`).

    Returns
    -------
    (SignatureLibrary, str)
    """
    def differs(a, b):
        return abs(a - b) > LOAD_TOLERANCE * max(abs(a), abs(b), 1e-9)

    if not (differs(op.torque_nm, machine.op.torque_nm)
            or differs(op.radial_load_n, machine.op.radial_load_n)):
        return lib, ""
    shift = operating_shift(machine, lib, op, threads=threads)
    if shift is None:
        return lib, ("the record's documented load differs from the machine's, and the model "
                     "at it diverged: read against the baseline as it is")
    shift = np.nan_to_num(shift)
    realisation, run_spread = (np.hypot(np.nan_to_num(v), OPERATING_SHIFT_UNCERTAINTY * shift)
                               for v in (lib.realisation, lib.run_spread))
    moved = replace(lib, mean=lib.mean + shift, realisation=realisation,
                    run_spread=run_spread, entries=tuple(
        replace(e, features=e.features + shift[None, :]) for e in lib.entries))
    return moved, (f"the record's documented load (torque {op.torque_nm:g} N m, radial load "
                   f"{op.radial_load_n:g} N) is not the machine's ({machine.op.torque_nm:g} N m,"
                   f" {machine.op.radial_load_n:g} N): the baseline is read moved by the "
                   "model's change between them, each feature within that change's own size")
