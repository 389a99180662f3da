"""``.tdms`` — NI TDMS (LabVIEW DAQ; npTDMS, ``pip install cmsim[tdms]``): one channel per TDMS
channel with data, named ``channel`` (one group) or ``group/channel``; the waveform property
``wf_increment`` gives the rate, ``unit_string`` the unit; scaling stored in the file is
applied (npTDMS)."""

from __future__ import annotations

import io

from cmsim._io import atomic_write_bytes
from cmsim.measured.readers._common import (SignalFile, channel_1d, one_rate, optional_module,
                                            rate_of_step)

__all__ = []   # read and write: through READERS and WRITERS of the package


def read(path, names=None):
    """Channels of an NI ``.tdms`` file and what it states (module docstring)."""
    nptdms = optional_module("nptdms", "tdms", path)
    f = nptdms.TdmsFile.read(str(path))
    groups = [g for g in f.groups() if any(len(c) for c in g.channels())]
    signals, units, rates = {}, {}, {}
    for g in groups:
        for c in g.channels():
            if not len(c):
                continue
            name = c.name if len(groups) == 1 else f"{g.name}/{c.name}"
            signals[name] = channel_1d(path, name, c[:])
            if c.properties.get("wf_increment"):
                rates[name] = rate_of_step(float(c.properties["wf_increment"]), digits=15)
            unit = str(c.properties.get("unit_string") or "").strip()
            if unit:
                units[name] = unit
    return SignalFile(signals, one_rate(path, rates), units, rate_from="its wf_increment")


def write(path, signals, rate_hz, units):
    """Write channels to an NI ``.tdms`` file that :func:`read` reads back the same, atomically."""
    nptdms = optional_module("nptdms", "tdms", path)
    chans = []
    for name, v in signals.items():
        props = {"wf_increment": 1.0 / float(rate_hz), "wf_start_offset": 0.0}
        if units.get(name):
            props["unit_string"] = units[name]
        chans.append(nptdms.ChannelObject("signals", name, v, properties=props))
    buf = io.BytesIO()
    with nptdms.TdmsWriter(buf) as w:
        w.write_segment([nptdms.GroupObject("signals")] + chans)
    atomic_write_bytes(path, buf.getvalue())
