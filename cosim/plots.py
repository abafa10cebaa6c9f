"""Figures of a run, in degrees for display: the layout of the paper's Figs 2-3."""
from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .master import Recording  # noqa: E402


def _deg(values: np.ndarray) -> np.ndarray:
    return np.degrees(values)


def course_keeping(recording: Recording, ax) -> None:
    t = recording.t
    ax[0].plot(t, recording["ship.u"], color="k")
    ax[0].set_ylabel("surge speed u (m/s)")
    ax[1].plot(t, _deg(recording["ship.psi"]), color="k", label="psi")
    ax[1].plot(t, _deg(recording["guidance.psi_d"]), "--", color="tab:red", label="psi_d")
    if "autopilot.psi_z" in recording.columns:
        ax[1].plot(t, _deg(recording["autopilot.psi_z"]), ":", color="tab:blue", label="psi_z")
    ax[1].set_ylabel("heading (deg)")
    ax[1].legend(loc="best")
    ax[2].plot(t, _deg(recording["ship.delta"]), color="k", linewidth=0.7)
    ax[2].set_ylabel("rudder delta (deg)")


def manoeuvre(recording: Recording, ax) -> None:
    t = recording.t
    ax[0].plot(recording["ship.y"], recording["ship.x"], color="k")
    ax[0].set_xlabel("east y (m)")
    ax[0].set_ylabel("north x (m)")
    ax[0].set_aspect("equal", adjustable="datalim")
    ax[1].plot(t, _deg(recording["ship.psi"]), color="k")
    ax[1].set_ylabel("heading (deg)")
    ax[2].plot(t, _deg(recording["ship.delta"]), color="k")
    ax[2].set_ylabel("rudder delta (deg)")


LAYOUTS = {"course_keeping": course_keeping, "turning_circle": manoeuvre, "zigzag": manoeuvre}


def save_figure(recording: Recording, report: str, path: Path, title: str) -> bool:
    """Write the figure for this kind of report; False if the kind has none."""
    if report not in LAYOUTS:
        return False
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), constrained_layout=True)
    LAYOUTS[report](recording, ax)
    for a in ax[1:] if report != "course_keeping" else ax:
        a.set_xlabel("time (s)")
        a.grid(alpha=0.3)
    ax[0].grid(alpha=0.3)
    fig.suptitle("\n".join(textwrap.wrap(title, 80)), fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True
