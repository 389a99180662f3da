"""Loss breakdown against speed, like paper 000 Figs. 53-57 (matplotlib imported lazily)."""

from __future__ import annotations

import math

import numpy as np

from cmsim.losses.breakdown import LOAD_DEPENDENT, LOAD_INDEPENDENT, loss_sweep

__all__ = ["loss_breakdown_figure", "run_losses_figure", "run_loss_rows"]

_LABELS = {"windage": "M_wind (windage)", "meshing": "M_mesh (pumping)",
           "oil_jet": "M_qm (oil jet)", "bearing_viscous": "M_b viscous",
           "bearing_load": "M_b load", "tooth_friction": "M_contact (tooth friction)",
           "damping": "damping (run: mesh, bearings, shafts)"}

#: Sources a run's resisting torques carry (constant torques: the run dissipates exactly
#: their quasi-static power at its mean speed).
_TORQUE_SOURCES = ("windage", "meshing", "oil_jet", "bearing_viscous", "bearing_load")


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


def run_loss_rows(losses):
    """Loss power by source of runs made with ``simulate(losses=...)``, W.

    Parameters
    ----------
    losses : sequence of dict
        Each run's ``meta["losses"]``.

    Returns
    -------
    list of dict
        Per run: the torque sources (windage, meshing, oil jet, bearing viscous and load
        terms: constant torques, so their quasi-static power), ``tooth_friction`` and
        ``damping`` from the run's own power balance (the quasi-static tooth friction when
        the run has no balance, e.g. a run-up, and no damping), ``total``, ``efficiency``
        and ``closure`` (None without a balance).
    """
    rows = []
    for info in losses:
        qs, bal = info["quasi_static"]["power_w"], info.get("balance")
        row = {k: float(qs.get(k, 0.0)) for k in _TORQUE_SOURCES}
        if bal:
            lw = bal["losses_w"]
            row["tooth_friction"] = float(lw.get("tooth_friction", 0.0))
            row["damping"] = float(sum(lw.get(k, 0.0) for k in ("mesh_damping", "bearings",
                                                                 "linear_damping")))
        else:
            row["tooth_friction"] = float(qs.get("tooth_friction", 0.0))
            row["damping"] = 0.0
        row["total"] = float(sum(row.values()))
        row["efficiency"] = float(bal["efficiency"] if bal
                                  else info["quasi_static"]["efficiency"])
        row["closure"] = float(bal["closure"]) if bal else None
        rows.append(row)
    return rows


def run_losses_figure(losses, labels, title="Power losses of the runs"):
    """Stacked loss power by source of each run, and the efficiency of each run.

    Parameters
    ----------
    losses : sequence of dict
        Each run's ``meta["losses"]`` (:func:`run_loss_rows`).
    labels : sequence of str
        One x-axis label per run (e.g. its speed and torque).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    rows = run_loss_rows(losses)
    keys = [k for k in _TORQUE_SOURCES + ("tooth_friction", "damping")
            if any(abs(r[k]) > 0 for r in rows)]
    x = np.arange(len(rows))
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2),
                                  gridspec_kw={"width_ratios": [2, 1]})
    bottom = np.zeros(len(rows))
    for k in keys:
        v = np.array([max(r[k], 0.0) for r in rows])
        ax.bar(x, v, bottom=bottom, label=_LABELS[k], width=0.7)
        bottom += v
    ax.set_xticks(x, labels, rotation=30 if len(rows) > 4 else 0, ha="right"
                  if len(rows) > 4 else "center", fontsize=8)
    ax.set_ylabel("loss power, W")
    ax.set_title(title)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3, axis="y")
    ax2.plot(x, [100 * r["efficiency"] for r in rows], "o-")
    ax2.set_xticks(x, labels, rotation=30 if len(rows) > 4 else 0, ha="right"
                   if len(rows) > 4 else "center", fontsize=8)
    ax2.set_ylabel("efficiency, %")
    ax2.set_title("efficiency (each run's power balance)")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return fig
