"""How a run is sampled: recorded duration, output rate, warm-up, integration substeps, seed.

:data:`SAMPLING` holds the one set of defaults that :func:`cmsim.dynamics.simulate`, the
command line (``simulate``, ``sweep``) and dataset specs share, so the same option means
the same thing everywhere: one second recorded at the paper's 75 kHz after a 50 ms warm-up,
the integration step chosen from the model's highest mode and fastest excitation
(:mod:`cmsim.dynamics.step`), and seed 0 (runs are
reproducible by default; give another seed for another realisation of the random parts).
"""

from __future__ import annotations

from dataclasses import dataclass

from cmsim.rig.ranges import RANGES

__all__ = ["Sampling", "SAMPLING"]


@dataclass(frozen=True)
class Sampling:
    """Sampling of one run.

    Attributes
    ----------
    duration_s : float
        Recorded duration, s.
    fs_hz : float
        Output sample rate, Hz.
    warmup_s : float
        Simulated time discarded before recording, s.
    substeps : int or None
        Integration steps per output sample; ``None`` = the fewest giving at least 4.7 steps
        per period of the model's highest mode and of 6 harmonics of its fastest excitation
        (:mod:`cmsim.dynamics.step`; then the output is anti-alias filtered).
    seed : int
        Seed of every random draw of the run (cage phases, slip, sensor noise).
    """

    duration_s: float = 1.0
    fs_hz: float = 75_000.0
    warmup_s: float = 0.05
    substeps: int | None = None
    seed: int = 0

    def __post_init__(self):
        for name in ("duration_s", "fs_hz", "warmup_s", "seed"):
            RANGES[name].check(name, getattr(self, name))
        if self.substeps is not None:
            RANGES["substeps"].check("substeps", self.substeps)


#: The defaults.
SAMPLING = Sampling()
