"""A machine's own healthy record, kept with the machine: the healthy prediction.

Condition monitoring trusts a machine's baseline, not a model of it: a record of the machine
is judged against the segments of its own healthy baseline and their segment-to-segment
spread, and a cause is judged by what the model says it changes on that baseline
(:mod:`cmsim.machine.change`). So the machine file keeps the baseline's samples, in the
sensor's unit, as float32 (the precision of the recordings cmsim reads), compressed.
"""

from __future__ import annotations

import base64
import math
import zlib
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError
from cmsim.features import segment_samples
from cmsim.features import segments as segment_spans

__all__ = ["Baseline"]


@dataclass(frozen=True, eq=False)
class Baseline:
    """The healthy record(s) a machine was calibrated on.

    Attributes
    ----------
    records : tuple of numpy.ndarray
        Each baseline record's samples (sensor unit, 1-D float32).
    fs_hz : float
        Sample rate, Hz.
    """

    records: tuple
    fs_hz: float

    def __post_init__(self):
        recs = tuple(np.ascontiguousarray(np.asarray(r, dtype=np.float32)) for r in
                     self.records)
        if not recs or any(r.ndim != 1 or r.size < 2 for r in recs):
            raise ParameterError("a baseline needs at least one 1-D record", param="baseline")
        if not all(np.all(np.isfinite(r)) for r in recs):
            raise ParameterError("a baseline record holds NaN or infinite samples",
                                 param="baseline")
        if not (math.isfinite(self.fs_hz) and self.fs_hz > 0):
            raise ParameterError(f"baseline fs_hz must be > 0, got {self.fs_hz!r}",
                                 param="baseline")
        for r in recs:
            r.setflags(write=False)
        object.__setattr__(self, "records", recs)
        object.__setattr__(self, "fs_hz", float(self.fs_hz))

    @property
    def duration_s(self):
        """Total length of the records, s."""
        return sum(r.size for r in self.records) / self.fs_hz

    def segments(self, segment_s, max_segments=None):
        """Consecutive segments of every record (none across two records), float64.

        Parameters
        ----------
        segment_s : float
            Segment length, s.
        max_segments : int, optional
            Most segments, shared among the records by their lengths and spread over each.

        Returns
        -------
        numpy.ndarray, shape (k, n)
        """
        n = segment_samples(self.fs_hz, segment_s)
        total = sum(r.size // n for r in self.records)
        out = []
        for r in self.records:
            share = None
            if max_segments is not None and total > max_segments:
                share = max(1, round(max_segments * (r.size // n) / total))
            out += [r[a:b] for a, b in segment_spans(r.size, self.fs_hz, segment_s, share)]
        if not out:
            raise ParameterError(f"the baseline holds no segment of {segment_s:g} s",
                                 param="baseline")
        return np.asarray(out, dtype=float)

    def piece(self, n, rng):
        """``n`` consecutive samples drawn from a random place of a random record (weighted
        by length), float64 — a healthy stretch of the machine for a dataset record.

        Parameters
        ----------
        n : int
            Samples (at most the longest record's).
        rng : numpy.random.Generator

        Returns
        -------
        numpy.ndarray, shape (n,)
        """
        fits = [r for r in self.records if r.size >= n]
        if not fits:
            longest = max(r.size for r in self.records) / self.fs_hz
            raise ParameterError(f"a record of {n / self.fs_hz:g} s is longer than the "
                                 f"machine's longest baseline record ({longest:g} s)",
                                 param="duration_s", allowed=f"<= {longest:g} s")
        sizes = np.array([r.size - n + 1 for r in fits], dtype=float)
        r = fits[int(rng.choice(len(fits), p=sizes / sizes.sum()))]
        start = int(rng.integers(0, r.size - n + 1))
        return np.asarray(r[start:start + n], dtype=float)

    def to_dict(self):
        """Plain dict for the machine file: each record zlib-compressed float32 (little
        endian) in base64, with its length and CRC-32."""
        return {"fs_hz": self.fs_hz,
                "records": [{"n": int(r.size), "crc32": zlib.crc32(r.astype("<f4").tobytes()),
                             "float32_zlib_base64": base64.b64encode(
                                 zlib.compress(r.astype("<f4").tobytes(), 6)).decode("ascii")}
                            for r in self.records]}

    @classmethod
    def from_dict(cls, data):
        """The baseline of :meth:`to_dict` output (lengths and checksums checked).

        Parameters
        ----------
        data : dict
            The machine file's ``[baseline]`` table.
        """
        recs = []
        for i, r in enumerate(data["records"]):
            try:
                raw = zlib.decompress(base64.b64decode(r["float32_zlib_base64"],
                                                       validate=True))
            except (ValueError, zlib.error) as exc:
                raise ParameterError(f"baseline record {i} is damaged ({exc})",
                                     param="machine") from None
            x = np.frombuffer(raw, dtype="<f4")
            if x.size != int(r["n"]) or zlib.crc32(raw) != int(r["crc32"]):
                raise ParameterError(f"baseline record {i} is damaged (its length or checksum "
                                     "does not match)", param="machine")
            recs.append(x.astype(np.float32))
        return cls(tuple(recs), float(data["fs_hz"]))
