"""A machine's twin: cmsim's model seen through one real machine's transfer path and
background, calibrated on a healthy baseline of that machine.

* :mod:`~cmsim.machine.path` — :class:`TransferPath`: model force → sensor, a minimum-phase
  filter applied in the time domain;
* :mod:`~cmsim.machine.background` — :class:`Background`: coloured noise and the lines the
  model does not make;
* :mod:`~cmsim.machine.machine` — :class:`Machine` (the machine file) and
  :func:`model_force`, :func:`rotating_force` and :func:`static_load` (the shaft forces of
  unbalance and misalignment);
* :mod:`~cmsim.machine.calibration` — :func:`calibrate` on healthy baseline records.
"""

from cmsim.machine.background import Background, BackgroundLine
from cmsim.machine.calibration import calibrate
from cmsim.machine.machine import (Machine, model_force, rotating_force, static_load,
                                   twin_mesh)
from cmsim.machine.path import TransferPath

__all__ = ["Background", "BackgroundLine", "Machine", "TransferPath", "calibrate",
           "model_force", "rotating_force", "static_load", "twin_mesh"]
