"""Figures of a run, in degrees for display: the layout of the paper's Figs 2-3."""
from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any, Callable

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..core.recording import Recording  # noqa: E402


def course_keeping_figure(recording: Recording, ax: Any) -> None:
    """Surge speed, heading against the desired course, rudder; over time."""
    t = recording.t
    ax[0].plot(t, recording["ship.u"], color="k")
    ax[0].set_ylabel("surge speed u (m/s)")
    ax[1].plot(t, np.degrees(recording["ship.psi"]), color="k", label="psi")
    ax[1].plot(t, np.degrees(recording["guidance.psi_d"]), "--", color="tab:red", label="psi_d")
    if "autopilot.psi_z" in recording.columns:
        ax[1].plot(t, np.degrees(recording["autopilot.psi_z"]), ":", color="tab:blue",
                   label="psi_z")
    ax[1].set_ylabel("heading (deg)")
    ax[1].legend(loc="best")
    ax[2].plot(t, np.degrees(recording["ship.delta"]), color="k", linewidth=0.7)
    ax[2].set_ylabel("rudder delta (deg)")
    for a in ax:
        a.set_xlabel("time (s)")


def manoeuvre_figure(recording: Recording, ax: Any) -> None:
    """The track (north up), heading and rudder over time."""
    t = recording.t
    ax[0].plot(recording["ship.y"], recording["ship.x"], color="k")
    ax[0].set_xlabel("east y (m)")
    ax[0].set_ylabel("north x (m)")
    ax[0].set_aspect("equal", adjustable="datalim")
    ax[1].plot(t, np.degrees(recording["ship.psi"]), color="k")
    ax[1].set_ylabel("heading (deg)")
    ax[2].plot(t, np.degrees(recording["ship.delta"]), color="k")
    ax[2].set_ylabel("rudder delta (deg)")
    for a in ax[1:]:
        a.set_xlabel("time (s)")


def save_figure(recording: Recording, draw: Callable[[Recording, Any], None], path: Path,
                title: str) -> Path:
    """Three panels drawn by ``draw``, titled, written to ``path``."""
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), constrained_layout=True)
    draw(recording, ax)
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("\n".join(textwrap.wrap(title, 80)), fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def comparison_figure(runs: dict[str, Recording], path: Path, title: str) -> Path:
    """Several controllers on one scenario: their tracks, headings and rudders, overlaid."""
    fig = plt.figure(figsize=(11, 6), constrained_layout=True)
    grid = fig.add_gridspec(2, 2, width_ratios=(1, 1.3))
    track, heading, rudder = (fig.add_subplot(grid[:, 0]), fig.add_subplot(grid[0, 1]),
                              fig.add_subplot(grid[1, 1]))
    first = next(iter(runs.values()))
    heading.plot(first.t, np.degrees(first["guidance.psi_d"]), "--", color="0.4",
                 label="psi_d")
    for label, run in runs.items():
        line, = track.plot(run["ship.y"], run["ship.x"], label=label)
        heading.plot(run.t, np.degrees(run["ship.psi"]), color=line.get_color(), label=label)
        rudder.plot(run.t, np.degrees(run["ship.delta"]), color=line.get_color(),
                    linewidth=0.7)
    track.set(xlabel="east y (m)", ylabel="north x (m)")
    track.set_aspect("equal", adjustable="datalim")
    track.legend(loc="best", fontsize=8)
    heading.set(ylabel="heading psi (deg)")
    heading.legend(loc="best", fontsize=8)
    rudder.set(xlabel="time (s)", ylabel="rudder delta (deg)")
    for a in (track, heading, rudder):
        a.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
