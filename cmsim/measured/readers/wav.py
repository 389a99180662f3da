"""``.wav`` — one channel per WAV channel, named by ``names`` (the entry's ``channels``) when
they match in number, else ``ch0``, ``ch1``, ...; the header rate is the sample rate. The
samples are read as stored (integer counts of a PCM file, floats of a float file). A
``LIST/INFO`` comment ``cmsim {"calibration": c, "channels": [...], "units": [...]}`` (what
:func:`write` writes) states channel names, units and the calibration factor ``c``
(physical value = ``c`` × stored sample), which is applied here; without it the factor may
come from ``metadata.json`` (``calibration`` of the entry, applied by
:func:`~cmsim.measured.record.read_record`)."""

from __future__ import annotations

import io
import json
import math
import struct

import numpy as np
from scipy.io import wavfile

from cmsim._io import atomic_write_bytes
from cmsim.errors import ParameterError
from cmsim.measured.readers._common import SignalFile

__all__ = []   # read and write: through READERS and WRITERS of the package


#: Prefix of the WAV ``LIST/INFO`` comment cmsim writes and reads.
_WAV_TAG = "cmsim "


def _chunks(path):
    """``(id, body, byte order)`` of each chunk of a RIFF/RIFX WAVE file, in order (none
    where it is not one)."""
    with open(path, "rb") as fh:
        head = fh.read(12)
        if len(head) < 12 or head[:4] not in (b"RIFF", b"RIFX") or head[8:12] != b"WAVE":
            return
        end = "<" if head[:4] == b"RIFF" else ">"
        while True:
            ck = fh.read(8)
            if len(ck) < 8:
                return
            cid, size = ck[:4], struct.unpack(end + "I", ck[4:])[0]
            if cid in (b"LIST", b"fmt "):
                yield cid, fh.read(size), end
                fh.seek(size & 1, 1)
            else:
                fh.seek(size + (size & 1), 1)


def _wav_comment(path):
    """The cmsim ``LIST/INFO/ICMT`` comment of a WAV file as a dict (empty without one)."""
    for cid, body, end in _chunks(path):
        if cid != b"LIST" or body[:4] != b"INFO":
            continue
        i = 4
        while i + 8 <= len(body):
            sid, ssize = body[i:i + 4], struct.unpack(end + "I", body[i + 4:i + 8])[0]
            text = body[i + 8:i + 8 + ssize].rstrip(b"\0").decode("utf-8", "replace")
            if sid == b"ICMT" and text.startswith(_WAV_TAG):
                return json.loads(text[len(_WAV_TAG):])
            i += 8 + ssize + (ssize & 1)
    return {}


def _bits_per_sample(path):
    """The ``fmt `` chunk's bits per sample (None where there is none)."""
    for cid, body, end in _chunks(path):
        if cid == b"fmt " and len(body) >= 16:
            return struct.unpack(end + "H", body[14:16])[0]
    return None


def read(path, names=None):
    """Channels of a ``.wav`` file and what it states (module docstring)."""
    rate, x = wavfile.read(path)
    if x.dtype == np.int32 and _bits_per_sample(path) == 24:
        # scipy gives 24-bit samples left-justified in 32 bits: 256 times the stored value,
        # which a calibration (units per stored value) is stated for
        x = x >> 8
    integer = x.dtype.kind in "iu"
    x = np.asarray(x, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    stated = _wav_comment(path)
    calibration = stated.get("calibration")
    if calibration is not None:
        x = x * float(calibration)
    names = list(stated.get("channels") or names or [])
    if len(names) != x.shape[1]:
        names = [f"ch{i}" for i in range(x.shape[1])]
    units = {n: u for n, u in zip(names, stated.get("units") or []) if u}
    return SignalFile({n: x[:, i] for i, n in enumerate(names)}, float(rate), units,
                      calibration=None if calibration is None else float(calibration),
                      rate_from="the WAV header",
                      counts=frozenset(names if integer and calibration is None else ()))


def write(path, signals, rate_hz, units):
    """Float32 WAV at full scale ±1: the samples divided by the largest magnitude, that
    factor stated as the calibration in a ``LIST/INFO`` comment with the names and units."""
    if float(rate_hz) != round(float(rate_hz)) or not 0 < rate_hz < 2 ** 32:
        raise ParameterError(f"a WAV header holds a whole sample rate, got {rate_hz:g} Hz; "
                             f"write .npz, .uff or .mat instead", param="rate_hz",
                             allowed="a whole number of Hz")
    names = list(signals)
    x = np.column_stack([np.asarray(signals[k], dtype=float) for k in names])
    peak = float(np.max(np.abs(x))) if x.size else 0.0
    calibration = peak if peak > 0 and math.isfinite(peak) else 1.0
    buf = io.BytesIO()
    wavfile.write(buf, int(rate_hz), (x / calibration).astype(np.float32))
    text = _WAV_TAG + json.dumps({"calibration": calibration, "channels": names,
                                  "units": [units.get(k) for k in names]})
    data = text.encode("utf-8") + b"\0"
    data += b"\0" * (len(data) & 1)
    info = b"INFO" + b"ICMT" + struct.pack("<I", len(data)) + data
    raw = bytearray(buf.getvalue()) + b"LIST" + struct.pack("<I", len(info)) + info
    raw[4:8] = struct.pack("<I", len(raw) - 8)
    atomic_write_bytes(path, bytes(raw))
