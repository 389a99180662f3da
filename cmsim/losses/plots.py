"""Loss breakdown against speed, like paper 000 Figs. 53-57 (matplotlib imported lazily)."""

from __future__ import annotations

import math

import numpy as np

from cmsim.losses.breakdown import LOAD_DEPENDENT, LOAD_INDEPENDENT, loss_sweep

__all__ = ["loss_breakdown_figure"]

_LABELS = {"windage": "M_wind (windage)", "meshing": "M_mesh (pumping)",
           "oil_jet": "M_qm (oil jet)", "bearing_viscous": "M_b viscous",
           "bearing_load": "M_b load", "tooth_friction": "M_contact (tooth friction)"}


def loss_breakdown_figure(rig, speeds_rpm, torque_nm, settings=None):
    """Stacked resisting torques referred to the input shaft against speed.

    Parameters
    ----------
    rig : Rig
    speeds_rpm : sequence of float
        Input speeds, rpm (paper 000: 1000-13000).
    torque_nm : float
        Output torque, N·m.
    settings : LossSettings, optional

    Returns
    -------
    matplotlib.figure.Figure
        Left: torque by source (N·m, power / input speed); right: efficiency.
    """
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    speeds = np.asarray(speeds_rpm, dtype=float)
    rows = loss_sweep(rig, speeds, torque_nm, settings)
    omega = speeds * math.pi / 30.0
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    keys = [k for k in LOAD_INDEPENDENT + LOAD_DEPENDENT
            if any(r.power_w.get(k, 0.0) > 0 for r in rows)]
    stack = np.array([[r.power_w.get(k, 0.0) for r in rows] for k in keys]) / omega
    ax.stackplot(speeds, stack, labels=[_LABELS[k] for k in keys], alpha=0.85)
    ax.plot(speeds, stack.sum(axis=0), "k-", lw=1.2, label="M_tot")
    ax.set_xlabel("input speed, rpm")
    ax.set_ylabel("resisting torque at the input, N m")
    ax.set_title(f"loss breakdown at {torque_nm:g} N m ({rig.name[:40]})")
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)
    ax2.plot(speeds, [100 * r.efficiency for r in rows], "o-")
    ax2.set_xlabel("input speed, rpm")
    ax2.set_ylabel("efficiency, %")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return fig
