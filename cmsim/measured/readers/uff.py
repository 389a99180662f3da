"""``.uff`` / ``.unv`` — Universal File Format, data sets of type 58 (what Siemens Testlab,
m+p and most modal/DAQ suites export; pyuff, ``pip install cmsim[uff]``): one channel per
set, named by its ``id1`` line (else ``response entity:node:direction``); the abscissa
increment is the sample spacing (its six printed digits rounded back to the rate they came
from), the ordinate unit label the unit. Sets must be evenly spaced time data at one rate;
a file with no type-58 set is refused."""

from __future__ import annotations

import gc
import os
import tempfile
import warnings
from pathlib import Path

import numpy as np

from cmsim.errors import ParameterError
from cmsim.measured.readers._common import (SignalFile, channel_1d, one_rate, optional_module,
                                            rate_of_step)

__all__ = []   # read and write: through READERS and WRITERS of the package


def _uff_text(value):
    text = str(value or "").strip()
    return "" if text.upper() == "NONE" else text


def read(path, names=None):
    """Channels of a UFF (``.uff``/``.unv``) file and what it states (module docstring)."""
    pyuff = optional_module("pyuff", "uff", path)
    uff = pyuff.UFF(str(path))
    types = [int(t) for t in np.atleast_1d(uff.get_set_types())]
    which = [i for i, t in enumerate(types) if t == 58]
    if not which:
        raise ParameterError(f"record {path}: holds no type-58 data set (function at nodal "
                             f"DOF, the time data Testlab and m+p export); its sets are of "
                             f"type {sorted(set(types)) or 'none'}: export the time "
                             f"histories as UFF 58", param="record",
                             allowed="a UFF file with type-58 sets")
    sets = uff.read_sets(which)
    sets = sets if isinstance(sets, list) else [sets]
    signals, units, rates = {}, {}, {}
    for s in sets:
        name = _uff_text(s.get("id1")) or (f"{_uff_text(s.get('rsp_ent_name')) or 'node'}:"
                                           f"{s.get('rsp_node')}:{s.get('rsp_dir')}")
        base, k = name, 2
        while name in signals:
            name, k = f"{base}_{k}", k + 1
        if not s.get("abscissa_spacing"):
            raise ParameterError(f"record {path}: set {name!r} has uneven abscissa spacing; "
                                 f"cmsim reads evenly sampled time data", param="record")
        signals[name] = channel_1d(path, name, s["data"])
        rates[name] = rate_of_step(s["abscissa_inc"], digits=6)
        unit = _uff_text(s.get("ordinate_axis_units_lab"))
        if unit:
            units[name] = unit
    return SignalFile(signals, one_rate(path, rates), units,
                      rate_from="its abscissa increment")


def write(path, signals, rate_hz, units):
    """Write channels to a UFF (``.uff``/``.unv``) file that :func:`read` reads back the same, atomically."""
    pyuff = optional_module("pyuff", "uff", path)
    sets = []
    for i, (name, v) in enumerate(signals.items()):
        v = np.asarray(v, dtype=float).reshape(-1)
        sets.append({"type": 58, "binary": 1, "id1": name, "id2": "cmsim",
                     "func_type": 1, "rsp_ent_name": name[:10], "rsp_node": i + 1,
                     "rsp_dir": 0, "ref_node": 0, "ref_dir": 0, "abscissa_spacing": 1,
                     "abscissa_spec_data_type": 17, "abscissa_axis_lab": "Time",
                     "abscissa_axis_units_lab": "s", "ordinate_spec_data_type": 0,
                     "ordinate_axis_lab": name[:20],
                     "ordinate_axis_units_lab": (units.get(name) or "NONE")[:20],
                     "orddenom_spec_data_type": 0, "data": v,
                     "x": np.arange(v.size) / float(rate_hz)})
    # pyuff writes by file name and appends (its "overwrite" mode garbles binary sets):
    # a fresh temporary name beside the target, then a rename
    fd, tmp = tempfile.mkstemp(prefix=f".{Path(path).name}.", suffix=".tmp",
                               dir=Path(path).parent)
    os.close(fd)
    os.unlink(tmp)
    try:
        with warnings.catch_warnings():   # pyuff leaves its text handle to the collector
            warnings.simplefilter("ignore", ResourceWarning)
            pyuff.UFF(tmp).write_sets(sets, mode="add")
            gc.collect()
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
