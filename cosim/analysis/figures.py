"""Figures of a run, in degrees: the track panel beside the signals over time, with eq (19)."""
from __future__ import annotations

import itertools
import math
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..core.files import whole_file
from ..core.recording import Recording
from .metrics import LAMBDA, cost, heading_error
from .reports import paper_row
from .track import legend_if_any, track_panel

RUDDER_LABEL = "rudder delta (deg)\n+ turns to port"     # a positive rudder turns to port
_VERDICT_COLOURS = {"PASS": "tab:green", "FAIL": "tab:red", "OPEN": "tab:orange"}


def new_figure(**options: Any) -> Figure:
    """A figure on an Agg canvas, made without pyplot: no backend chosen, nothing kept."""
    fig = Figure(**options)
    FigureCanvasAgg(fig)
    return fig


def _layout(ylabels: tuple[str, ...], heights: tuple[float, ...] | None = None
            ) -> tuple[Figure, Any, list[Any]]:
    fig = new_figure(figsize=(13, 8), layout="constrained")
    grid = fig.add_gridspec(len(ylabels), 2, width_ratios=(1.0, 1.25), height_ratios=heights)
    track = fig.add_subplot(grid[:, 0])
    track.grid(alpha=0.3)
    return fig, track, time_axes(fig, [grid[i, 1] for i in range(len(ylabels))], ylabels,
                                   fontsize=9)


def time_axes(fig: Figure, cells: list[Any], ylabels: tuple[str, ...], **label: Any
              ) -> list[Any]:
    """Panels over time, one per grid cell, sharing the time axis, with their y labels."""
    axes = [fig.add_subplot(cells[0])]
    axes += [fig.add_subplot(c, sharex=axes[0]) for c in cells[1:]]
    for a, ylabel in zip(axes, ylabels):
        a.grid(alpha=0.3)
        a.tick_params(labelbottom=a is axes[-1])
        a.set_ylabel(ylabel, **label)
    axes[-1].set_xlabel("time (s)")
    return axes


def text_grid(width_ratios: tuple[float, float], rows: int, text: list[str]
              ) -> tuple[Figure, Any]:
    """A figure and its grid: ``rows`` rows of panels above one row of ``text``."""
    text_lines = sum(line.count("\n") + 1 for line in _wrapped(text))
    fig = new_figure(figsize=(13, 8.5 + 0.14 * text_lines), layout="constrained")
    panel = (8.0 - 0.3 * rows) / rows
    return fig, fig.add_gridspec(rows + 1, 2, width_ratios=width_ratios,
                                 height_ratios=(*[panel] * rows, 0.16 * text_lines + 0.2))


def _wrapped(lines: list[str]) -> list[str]:
    return [textwrap.fill(line, 150, subsequent_indent="      ", break_on_hyphens=False)
            for line in lines]


def text_panel(ax: Any, lines: list[str]) -> None:
    """The report's lines, wrapped; a verdict in its colour."""
    ax.set_axis_off()
    shown = _wrapped(lines)
    heights = [line.count("\n") + 1 for line in shown]
    for line, row in zip(shown, itertools.accumulate(heights, initial=0)):
        ax.text(0.0, 1.0 - row / sum(heights), line, transform=ax.transAxes, va="top",
                ha="left", fontsize=8, family="monospace",
                color=_VERDICT_COLOURS.get(line.split(" ", 1)[0], "black"))


def merit_table(run: Recording, lam: float = LAMBDA) -> str:
    """Eq (19) of the run as a table, with the paper's values for one of its own runs."""
    c = cost(run, lam)
    rows = [("eq (19), rad^2", "psi_E", "delta_E", "J"),
            ("this run", f"{c.psi_E:.2f}", f"{c.delta_E:.2f}", f"{c.J:.2f}")]
    paper = paper_row(run.meta)
    if paper is not None:
        rows.append((paper[0], *(f"{v:.2f}" for v in paper[1])))
    lines = [f"{name:<22}{a:>9}{b:>9}{j:>9}" for name, a, b, j in rows]
    lines.append(f"delta_E = lambda sum delta^2 = {c.lam:.4f} x {c.sum_delta2:.3f}")
    return "\n".join(lines)


def course_keeping_figure(run: Recording, lam: float = LAMBDA) -> Figure:
    """Track with eq (19); surge speed, heading, heading error, yaw rate and rudder."""
    fig, track, (u, heading, error, r, rudder) = _layout(
        ("surge u (m/s)", "heading (deg)", "psi_d - psi (deg)", "yaw rate r (deg/s)",
         RUDDER_LABEL), heights=(1, 1, 1, 1, 1.5))
    track_panel(track, run)
    track.set_title(merit_table(run, lam), loc="left", family="monospace", fontsize=8)
    t = run.t
    u.plot(t, run["ship.u"], color="k")
    for column, color, label in (("sensors.psi_m", "tab:green", "psi measured"),
                                 ("observer.psi_hat", "tab:purple", "psi_hat, observer")):
        if column in run.columns:                       # what the autopilot was told
            heading.plot(t, np.degrees(run[column]), color=color, linewidth=0.5, label=label)
    heading.plot(t, np.degrees(run["ship.psi"]), color="k", label="psi")
    heading.plot(t, np.degrees(run["guidance.psi_d"]), "--", color="tab:red", label="psi_d")
    if "autopilot.psi_z" in run.columns:
        heading.plot(t, np.degrees(run["autopilot.psi_z"]), ":", color="tab:blue", label="psi_z")
    legend_if_any(heading)
    error.plot(t, np.degrees(heading_error(run["guidance.psi_d"], run["ship.psi"])), color="k")
    r.plot(t, np.degrees(run["ship.r"]), color="k", label="r")
    if "observer.r_hat" in run.columns:
        r.plot(t, np.degrees(run["observer.r_hat"]), color="tab:purple", linewidth=0.7,
               label="r_hat, observer")
        legend_if_any(r)
    command = np.degrees(run["ship.delta_c"])
    rudder.plot(t, command, color="tab:orange", linewidth=0.5, alpha=0.55, zorder=1,
                label="commanded delta_c")
    rudder.plot(t, np.degrees(run["ship.delta"]), color="k", linewidth=0.9, zorder=3,
                label="actual delta")
    stops = math.degrees(run.meta.get("parameters", {}).get("ship", {}).get("delta_max", math.pi))
    if np.abs(command).max() > 1.15 * stops:            # a chattering command: the rudder shown
        rudder.set_ylim(-1.15 * stops, 1.15 * stops)
        for level in (-stops, stops):
            rudder.axhline(level, color="0.5", linestyle=":", linewidth=0.8, zorder=2)
        rudder.set_title(f"command up to {np.abs(command).max():.0f} deg, clipped here; "
                         f"dotted: the stops at +-{stops:.0f} deg", loc="left", fontsize=7,
                         color="tab:orange")
    legend_if_any(rudder)
    events: dict[float, list[str]] = {}                 # timed events: a line through time
    for e in run.meta.get("events", []):
        events.setdefault(e["time"], []).append(f"{e['action']} {e['variable']}")
    for time, what in events.items():
        for ax in (u, heading, error, r, rudder):
            ax.axvline(time, color="tab:purple", linestyle="-.", linewidth=0.8)
        u.annotate(", ".join(what), (time, 1.0), xycoords=("data", "axes fraction"),
                   fontsize=6, color="tab:purple", va="bottom", rotation=15)
    return fig


def save(fig: Figure, path: Path, formats: tuple[str, ...] = ("png",)) -> list[Path]:
    """Write the figure in each format (path with that suffix), each file whole or not at all."""
    written = [path.with_suffix(f".{fmt}") for fmt in formats]
    for target, fmt in zip(written, formats):
        with whole_file(target) as tmp:
            fig.savefig(tmp, dpi=120, format=fmt)
    return written


def comparison(runs: dict[str, Recording], caption: str) -> Figure:
    """Several controllers on one scenario: their tracks, headings and rudders, overlaid."""
    fig, track, (heading, rudder) = _layout(("heading psi (deg)", RUDDER_LABEL))
    first = next(iter(runs.values()))
    track_panel(track, first, ship=False, others=runs.values())    # the route and the waves
    heading.plot(first.t, np.degrees(first["guidance.psi_d"]), "--", color="0.4", label="psi_d")
    for label, run in runs.items():
        line, = track.plot(run["ship.y"], run["ship.x"], label=label)
        heading.plot(run.t, np.degrees(run["ship.psi"]), color=line.get_color(), label=label)
        rudder.plot(run.t, np.degrees(run["ship.delta"]), color=line.get_color(), linewidth=0.7)
    legend_if_any(track)
    legend_if_any(heading)
    fig.suptitle(caption, fontsize=10)
    return fig
