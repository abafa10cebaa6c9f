"""Figures of a run, in degrees for display: where the ship went, and how it got there.

Every course-keeping and manoeuvre figure has a track panel, north up and east
right at equal scale: the track, the route with its circles of acceptance, where
each leg switched, the ship's outline to scale at regular times, and the direction
the waves travel to. Beside it, the signals over time. The figures take what they
show from the recording: its columns, and the parameter values the run used
(``Recording.meta``), never from what a scenario is supposed to be.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Callable

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Circle, Polygon  # noqa: E402

from autopilot_fmu.guidance import route as followed_route  # noqa: E402
from ship_fmu.data import Hull  # noqa: E402

from ..core.files import whole_file  # noqa: E402
from ..core.recording import Recording  # noqa: E402
from .describe import title  # noqa: E402
from .manoeuvres import crossing, turning_circle_figures, zigzag_figures  # noqa: E402
from .metrics import heading_error  # noqa: E402

FORMATS = ("png", "svg", "pdf")
OUTLINES = 12
"""Ship outlines drawn along a track, about."""


def hull_outline(x: float, y: float, psi: float) -> np.ndarray:
    """The ship's waterline to scale, pointed bow, as (east, north) corners at (x, y, psi)."""
    L, B = Hull.L, Hull.B
    body = np.array([(L / 2, 0.0), (L / 4, B / 2), (-L / 2, B / 2), (-L / 2, -B / 2),
                     (L / 4, -B / 2)])                  # x forward, y starboard
    c, s = math.cos(psi), math.sin(psi)
    north = x + body[:, 0] * c - body[:, 1] * s
    east = y + body[:, 0] * s + body[:, 1] * c
    return np.column_stack([east, north])


def track_panel(ax: Any, run: Recording, ship: bool = True) -> None:
    """The route with its circles of acceptance, the wave direction and, with ``ship``, the
    track, where each leg switched and the ship's outline to scale at regular times."""
    p = run.meta.get("parameters", {})
    x, y, psi, t = run["ship.x"], run["ship.y"], run["ship.psi"], run.t
    if ship:
        ax.plot(y, x, color="k", linewidth=1.0, label="track", zorder=3)
    if "guidance" in p:
        points = np.array(followed_route(p["guidance"]))
        ax.plot(points[:, 1], points[:, 0], "--o", color="tab:blue", linewidth=0.8,
                markersize=4, label="route", zorder=2)
        for north, east in points[1:]:
            ax.add_patch(Circle((east, north), p["guidance"]["R_accept"], fill=False,
                                linestyle=":", color="tab:blue", zorder=2))
        if ship:
            switched = np.flatnonzero(np.diff(run["guidance.wp_index"])) + 1
            ax.plot(y[switched], x[switched], "x", color="tab:red", markersize=8, mew=2,
                    label="leg switched", zorder=4)
    if ship:
        every = max(1.0, round((t[-1] - t[0]) / OUTLINES / 10.0) * 10.0)
        stride = max(1, round(every / run.meta.get("step_size", t[1] - t[0])))
        drawn: list[tuple[float, float]] = []
        for k in range(0, len(t), stride):      # not on top of one drawn a lap earlier
            if all(math.hypot(x[k] - a, y[k] - b) > Hull.L for a, b in drawn):
                drawn.append((x[k], y[k]))
                ax.add_patch(Polygon(hull_outline(x[k], y[k], psi[k]), closed=True,
                                     facecolor="0.55", edgecolor="k", linewidth=0.6,
                                     zorder=3))
        ax.plot([], [], "s", color="0.55", markeredgecolor="k",
                label=f"ship to scale, every {every:g} s")
    sea = p.get("ship", {})
    if sea.get("Hs", 0.0) > 0.0:
        direction = sea["psi_w"]
        tail = (0.9 - 0.07 * math.sin(direction), 0.86 - 0.07 * math.cos(direction))
        ax.annotate("", xy=(0.9 + 0.07 * math.sin(direction), 0.86 + 0.07 * math.cos(direction)),
                    xytext=tail, xycoords="axes fraction",
                    arrowprops=dict(arrowstyle="->", color="tab:cyan", linewidth=2))
        ax.text(*tail, "waves ", transform=ax.transAxes, ha="right", va="center", fontsize=8,
                color="tab:cyan")
    ax.set(xlabel="east y (m)", ylabel="north x (m)")
    ax.set_aspect("equal", adjustable="datalim")
    legend_if_any(ax)


def legend_if_any(ax: Any, **kwargs: Any) -> None:
    """A legend, if anything in the axes has a label to show."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(**{"loc": "best", "fontsize": 7, "framealpha": 0.9, **kwargs})


def _layout(panels: int) -> tuple[Figure, Any, list[Any]]:
    """A track panel on the left, ``panels`` time panels sharing the time axis on the right."""
    fig = plt.figure(figsize=(13, 8), constrained_layout=True)
    grid = fig.add_gridspec(panels, 2, width_ratios=(1.0, 1.25))
    track = fig.add_subplot(grid[:, 0])
    right = [fig.add_subplot(grid[0, 1])]
    right += [fig.add_subplot(grid[i, 1], sharex=right[0]) for i in range(1, panels)]
    for a in right[:-1]:
        a.tick_params(labelbottom=False)
    right[-1].set_xlabel("time (s)")
    for a in (track, *right):
        a.grid(alpha=0.3)
    return fig, track, right


def _degrees(ax: Any, run: Recording, column: str, label: str) -> None:
    """One signal over time, in degrees, black, labelled."""
    ax.plot(run.t, np.degrees(run[column]), color="k")
    ax.set_ylabel(label)


def _rudder(ax: Any, run: Recording, commanded: str) -> None:
    """Commanded and actual rudder; the scale is the stops', a larger command is clipped."""
    command = np.degrees(run[commanded])
    ax.plot(run.t, command, color="tab:orange", linewidth=0.7, label="commanded delta_c")
    ax.plot(run.t, np.degrees(run["ship.delta"]), color="k", linewidth=0.9, label="actual delta")
    stops = math.degrees(run.meta.get("parameters", {}).get("ship", {}).get("delta_max", math.pi))
    if np.abs(command).max() > 1.15 * stops:
        ax.set_ylim(-1.15 * stops, 1.15 * stops)
        ax.text(0.01, 0.03, f"commanded up to {np.abs(command).max():.0f} deg, beyond the "
                f"stops at +-{stops:.0f} deg (clipped here)", transform=ax.transAxes,
                fontsize=7, color="tab:orange", zorder=5,
                bbox=dict(boxstyle="round", facecolor="white", alpha=0.9, edgecolor="none"))
    ax.set_ylabel("rudder (deg)")
    legend_if_any(ax, loc="upper right")


def course_keeping_figure(run: Recording) -> Figure:
    """Track; surge speed, heading, heading error, yaw rate, commanded and actual rudder."""
    fig, track, (u, heading, error, r, rudder) = _layout(5)
    track_panel(track, run)
    t = run.t
    u.plot(t, run["ship.u"], color="k")
    u.set_ylabel("surge u (m/s)")
    heading.plot(t, np.degrees(run["ship.psi"]), color="k", label="psi")
    heading.plot(t, np.degrees(run["guidance.psi_d"]), "--", color="tab:red", label="psi_d")
    if "autopilot.psi_z" in run.columns:
        heading.plot(t, np.degrees(run["autopilot.psi_z"]), ":", color="tab:blue",
                     label="psi_z")
    heading.set_ylabel("heading (deg)")
    legend_if_any(heading)
    error.plot(t, np.degrees(heading_error(run["guidance.psi_d"], run["ship.psi"])), color="k")
    error.set_ylabel("psi_d - psi (deg)")
    _degrees(r, run, "ship.r", "yaw rate r (deg/s)")
    _rudder(rudder, run, "ship.delta_c")
    return fig


def turning_circle_figure(run: Recording) -> Figure:
    """Track with advance, transfer and tactical diameter marked; heading, yaw rate, rudder."""
    fig, track, (heading, r, rudder) = _layout(3)
    track_panel(track, run)
    x, y, psi = run["ship.x"], run["ship.y"], run["ship.psi"]
    tc = turning_circle_figures(*(run[f"ship.{n}"] for n in ("x", "y", "psi", "u", "v", "r")))
    x90, y90 = crossing(x, y, psi, math.pi / 2)
    x180, y180 = crossing(x, y, psi, math.pi)
    x0, y0 = x[0], y[0]
    u_end, v_end, r_end = (run[f"ship.{n}"][-1] for n in ("u", "v", "r"))
    track.plot([y0, y0], [x0, x90], color="tab:green", linewidth=2.5,
               label=f"advance {tc.advance:.2f} m (at 90 deg)")
    track.plot([y0, y90], [x90, x90], color="tab:purple", linewidth=2.5,
               label=f"transfer {tc.transfer:.2f} m (at 90 deg)")
    track.plot([y0, y180], [x180, x180], color="tab:brown", linewidth=2.5,
               label=f"tactical diameter {tc.tactical_diameter:.2f} m (at 180 deg)")
    # IMO measures these at heading changes; with a large drift angle the heading leads the
    # velocity, so the steady circle is wider than the tactical diameter: say so.
    track.text(0.02, 0.02, f"steady turn: drift angle "
               f"{math.degrees(math.atan2(v_end, u_end)):.0f} deg, diameter 2U/|r| = "
               f"{2 * math.hypot(u_end, v_end) / abs(r_end):.2f} m",
               transform=track.transAxes, fontsize=8,
               bbox=dict(boxstyle="round", facecolor="white", alpha=0.9, edgecolor="none"))
    legend_if_any(track)
    _degrees(heading, run, "ship.psi", "heading (deg)")
    _degrees(r, run, "ship.r", "yaw rate r (deg/s)")
    r.axhline(math.degrees(tc.steady_yaw_rate), linestyle=":", color="tab:gray")
    _rudder(rudder, run, "ship.delta_c")
    return fig


def zigzag_figure(run: Recording) -> Figure:
    """Track; heading with the switching angles, the execute points and both overshoots."""
    fig, track, (heading, r, rudder) = _layout(3)
    track_panel(track, run)
    t, psi = run.t, np.degrees(run["ship.psi"])
    switch = run.meta["parameters"]["program"]["psi_switch"]
    zz = zigzag_figures(run["ship.psi"], run["program.reversals"], switch)
    reversals = run["program.reversals"]
    heading.plot(t, psi, color="k", label="psi")
    for level in (-math.degrees(switch), math.degrees(switch)):
        heading.axhline(level, linestyle=":", color="tab:gray")
    executed = [0, *(np.flatnonzero(np.diff(reversals)) + 1)]
    heading.plot(t[executed], psi[executed], "v", color="tab:red",
                 label="rudder executed, reversed")
    words = []
    for n, overshoot in ((1, zz.first_overshoot), (2, zz.second_overshoot)):
        if math.isnan(overshoot):
            words.append(f"no reversal {n + 1}: the turn was never checked")
            break
        k = np.flatnonzero(reversals == n)[np.argmax(np.abs(psi[reversals == n]))]
        level = math.copysign(math.degrees(switch), psi[k])
        heading.annotate("", xy=(t[k], psi[k]), xytext=(t[k], level),
                         arrowprops=dict(arrowstyle="<->", color="tab:red"))
        heading.text(t[k], psi[k], f" {n}", color="tab:red", fontsize=8,
                     va="top" if psi[k] < 0 else "bottom")
        words.append(f"overshoot {n}: {math.degrees(overshoot):.1f} deg")
    heading.text(0.99, 0.03, "\n".join(words), transform=heading.transAxes, ha="right",
                 fontsize=8, color="tab:red",
                 bbox=dict(boxstyle="round", facecolor="white", alpha=0.9, edgecolor="none"))
    heading.set_ylabel("heading (deg)")
    legend_if_any(heading)
    _degrees(r, run, "ship.r", "yaw rate r (deg/s)")
    _rudder(rudder, run, "ship.delta_c")
    return fig


def save(fig: Figure, path: Path, formats: tuple[str, ...] = ("png",)) -> list[Path]:
    """Write the figure in each format (path with that suffix), each file whole or not at all."""
    written = []
    try:
        for fmt in formats:
            if fmt not in FORMATS:
                raise ValueError(f"figure format {fmt!r}: one of {', '.join(FORMATS)}")
            target = path.with_suffix(f".{fmt}")
            with whole_file(target) as tmp:
                fig.savefig(tmp, dpi=120, format=fmt)
            written.append(target)
    finally:
        plt.close(fig)
    return written


def save_figure(run: Recording, draw: Callable[[Recording], Figure], path: Path, label: str,
                formats: tuple[str, ...] = ("png",)) -> list[Path]:
    """Draw a run's figure, title it from what the run used, write it in each format."""
    fig = draw(run)
    fig.suptitle(title(label, run.meta), fontsize=8)
    return save(fig, path, formats)


def comparison_figure(runs: dict[str, Recording], path: Path, title: str) -> Path:
    """Several controllers on one scenario: their tracks, headings and rudders, overlaid."""
    fig, track, (heading, rudder) = _layout(2)
    first = next(iter(runs.values()))
    track_panel(track, first, ship=False)       # the route and the waves
    heading.plot(first.t, np.degrees(first["guidance.psi_d"]), "--", color="0.4",
                 label="psi_d")
    for label, run in runs.items():
        line, = track.plot(run["ship.y"], run["ship.x"], label=label)
        heading.plot(run.t, np.degrees(run["ship.psi"]), color=line.get_color(), label=label)
        rudder.plot(run.t, np.degrees(run["ship.delta"]), color=line.get_color(),
                    linewidth=0.7)
    legend_if_any(track)
    heading.set(ylabel="heading psi (deg)")
    legend_if_any(heading)
    rudder.set(ylabel="rudder delta (deg)")
    fig.suptitle(title, fontsize=10)
    return save(fig, path)[0]
