"""Anti-alias decimation: integrate fast, record at the acquisition rate without aliasing.

The integration step is set by the model's stiffest mode, the output sample rate by the user
(an acquisition rate such as 25.6 kHz). When the step is a fraction ``1/k`` of the output
interval, keeping every k-th state would fold everything above the output Nyquist frequency
back into the band (a 5×GMF line reads as "5BPFO+2fr"). :class:`AntiAliasFilter` is the
linear-phase FIR low-pass of an acquisition system: flat (ripple below 0.01 dB) up to
``passband`` × Nyquist, at least ``attenuation_db`` down from the output Nyquist frequency
on, so that nothing above Nyquist can alias into the band. It is applied centred on each
output instant (zero phase): output sample m is the filtered signal at exactly
``t0 + m·k·h``.

References
----------
.. [1] J. F. Kaiser, "Nonrecursive digital filter design using the I0-sinh window function",
   Proc. IEEE ISCAS (1974) 20-23 (the Kaiser window design rule of
   :func:`scipy.signal.kaiserord`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import firwin, kaiserord

from cmsim.dynamics._decimation_kernels import fir_decimate_jit
from cmsim.errors import ParameterError, check_range

__all__ = ["AntiAliasFilter"]


@dataclass(frozen=True)
class AntiAliasFilter:
    """Linear-phase FIR low-pass for decimation by an integer factor.

    Attributes
    ----------
    factor : int
        Decimation factor k (integration steps per output sample), >= 2.
    fs_in_hz : float
        Input (integration) sample rate, Hz.
    attenuation_db : float
        Stop-band attenuation from the output Nyquist frequency on, dB.
    passband : float
        Pass-band edge as a fraction of the output Nyquist frequency (0.8: an acquisition
        system's usual fs = 2.56·f_max).
    taps : ndarray, shape (N,)
        Filter coefficients; N − 1 is a multiple of 2k so the filter is centred on output
        instants.
    """

    factor: int
    fs_in_hz: float
    attenuation_db: float = 80.0
    passband: float = 0.8
    taps: np.ndarray = field(init=False, repr=False)
    _taps_flipped: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if isinstance(self.factor, bool) or not isinstance(self.factor, (int, np.integer)) \
                or self.factor < 2:
            raise ParameterError(f"factor must be an integer >= 2, got {self.factor!r}")
        check_range("fs_in_hz", self.fs_in_hz, 0.0, lo_open=True, unit="Hz")
        check_range("attenuation_db", self.attenuation_db, 20.0, 200.0, unit="dB")
        check_range("passband", self.passband, 0.1, 0.95)
        nyq_out = 0.5 * self.fs_in_hz / self.factor
        width = (1.0 - self.passband) * nyq_out / (0.5 * self.fs_in_hz)
        numtaps, beta = kaiserord(self.attenuation_db, width)
        step = 2 * self.factor
        numtaps = step * math.ceil((numtaps - 1) / step) + 1
        cutoff = 0.5 * (1.0 + self.passband) * nyq_out
        taps = firwin(numtaps, cutoff, window=("kaiser", beta), fs=self.fs_in_hz)
        taps.setflags(write=False)
        object.__setattr__(self, "taps", taps)
        object.__setattr__(self, "_taps_flipped", np.ascontiguousarray(taps[::-1]))

    @property
    def half_length(self):
        """Input samples needed on each side of an output instant, (N − 1)/2."""
        return (self.taps.size - 1) // 2

    @property
    def fs_out_hz(self):
        """Output sample rate, Hz."""
        return self.fs_in_hz / self.factor

    @property
    def passband_hz(self):
        """Pass-band edge, Hz."""
        return self.passband * 0.5 * self.fs_out_hz

    def apply(self, x):
        """Filter and decimate the columns of ``x``.

        Parameters
        ----------
        x : ndarray, shape (L, C)
            Input samples; row ``half_length + m·factor`` is output instant m. A C-contiguous
            float64 block is read in place; anything else is copied into one first.

        Returns
        -------
        ndarray, shape ((L − 2·half_length − 1) // factor + 1, C)
            Filtered samples at the output instants that have a full window (the
            :func:`scipy.signal.upfirdn` result, bit for bit).
        """
        x = np.asarray(x, dtype=float)
        one = x.ndim == 1
        if one:
            x = x[:, None]
        hl = self.half_length
        n_out = max((x.shape[0] - 2 * hl - 1) // self.factor + 1, 0)
        x = np.ascontiguousarray(x)
        out = np.empty((n_out, x.shape[1]))
        if n_out and x.shape[1]:
            fir_decimate_jit(x.reshape(-1), x.shape[1], self._taps_flipped, int(self.factor),
                             out)
        return out[:, 0] if one else out

    def to_dict(self):
        """JSON-ready description for a run's metadata."""
        return {"factor": int(self.factor), "fs_in_hz": float(self.fs_in_hz),
                "numtaps": int(self.taps.size), "passband_hz": float(self.passband_hz),
                "stopband_hz": float(0.5 * self.fs_out_hz),
                "attenuation_db": float(self.attenuation_db)}
