"""IMO-style plates of a zig-zag and a turning circle (MSC/Circ.1053) with the MSC.137(76)
criteria in the words of ``reports``; the rudder drawn as -delta, in the heading's sense."""
from __future__ import annotations

import math
from functools import partial
from typing import Any, Callable

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from ship_fmu.data import Hull

from ..core.recording import Recording
from .figures import text_grid, text_panel, time_axes
from .manoeuvres import (approach_frame, at_heading_change, steady_circle, turning_circle_of,
                         zigzag_of)
from .reports import turning_circle_report, zigzag_report
from .track import hull_outline, legend_if_any, outlines, to_earth, track_panel

_ORDINALS = ("1st", "2nd", "3rd", "4th")
_BOX = dict(boxstyle="round,pad=0.15", facecolor="white", alpha=0.85, edgecolor="none")
_ROUND = {**_BOX, "boxstyle": "round"}
_BOTH_WAYS = dict(arrowstyle="<->", shrinkA=0, shrinkB=0)


def _rudder(ax: Any, run: Recording) -> None:
    ax.plot(run.t, -np.degrees(run["ship.delta_c"]), "--", color="tab:blue", linewidth=0.7,
            label="rudder ordered")
    ax.plot(run.t, -np.degrees(run["ship.delta"]), color="tab:blue", linewidth=1.2, label="rudder")


def zigzag_plate(run: Recording, **_: Any) -> Figure:
    """Heading and rudder with executes, overshoots and times; yaw rate; track; criteria."""
    a = zigzag_of(run)
    zz, switch = a.figures, math.degrees(a.figures.psi_switch)
    lines = zigzag_report(run)
    fig, grid = text_grid((2.2, 1.0), 3, lines)
    heading, r = time_axes(fig, [grid[0:2, 0], grid[2, 0]], (
        "heading psi, rudder -delta (deg, + turns to starboard)", "yaw rate r (deg/s)"))
    track_panel(fig.add_subplot(grid[0:3, 1]), run)
    t, psi = run.t, np.degrees(run["ship.psi"])
    heading.plot(t, psi, color="k", linewidth=1.4, label="heading psi")
    _rudder(heading, run)
    heading.axhline(0.0, color="0.6", linewidth=0.6)
    for level in (-switch, switch):                             # where the rudder reverses
        heading.axhline(level, linestyle=":", color="0.4", linewidth=0.9)
        heading.text(1.0, level, f" {level:+g}", transform=heading.get_yaxis_transform(),
                     va="center", fontsize=7, color="0.4")
    executed = psi[np.searchsorted(t, zz.executes)]
    heading.plot(zz.executes, executed, "o", color="tab:red", markersize=4, zorder=5,
                 label="execute (rudder ordered)")
    for name, when, at in zip(_ORDINALS, zz.executes, executed):
        heading.annotate(f"{name} execute", (when, at), textcoords="offset points",
                         xytext=(4, -10 if at <= 0 else 4), fontsize=7, color="tab:red")
    for n, o in enumerate(zz.overshoots):
        peak = math.degrees(o.heading)
        heading.annotate("", xy=(o.time, peak), xytext=(o.time, math.copysign(switch, peak)),
                         arrowprops=dict(color="tab:purple", **_BOTH_WAYS))
        if n < 2:
            heading.annotate(f"{_ORDINALS[n]} overshoot {math.degrees(o.angle):.1f} deg",
                             (o.time, peak), textcoords="offset points", fontsize=7,
                             xytext=(5, -9 if peak < 0 else 3), color="tab:purple", bbox=_BOX)
    if zz.running is not None:          # framed on where the heading leaves the plate
        limit = 6.0 * max(switch, math.degrees(a.delta))
        heading.set_ylim(-limit, limit)
        gone = int(np.argmax(np.abs(psi) > limit)) if np.abs(psi).max() > limit else len(t) - 1
        heading.set_xlim(t[0], min(t[-1], t[0] + 4.0 * (t[gone] - t[0])))
        side = math.copysign(1.0, psi[-1])
        heading.annotate(f"heading {psi[-1]:.0f} deg at t = {t[-1]:.0f} s, still going away: "
                         "the turn was not checked within the run", xy=(t[gone], side * limit),
                         xytext=(t[0] + 1.15 * (t[gone] - t[0]), side * 0.75 * limit),
                         fontsize=8, color="tab:red", arrowprops=dict(arrowstyle="->",
                                                                      color="tab:red"))
    elif len(zz.executes) >= 6:         # zoomed on the first five executes
        end = zz.executes[5] + 0.25 * (zz.executes[5] - zz.executes[4])
        shown = psi[t <= end]
        rudder = math.degrees(np.abs(run["ship.delta"]).max())
        margin = 0.1 * (shown.max() - shown.min())
        heading.set_xlim(t[0], end)
        heading.set_ylim(min(shown.min(), -rudder) - margin, max(shown.max(), rudder) + margin)
        heading.text(0.99, 0.99, f"first {end - t[0]:.0f} s of {t[-1] - t[0]:.0f} s; the "
                     "track shows all", transform=heading.transAxes, ha="right", va="top",
                     fontsize=7, color="0.4", bbox=_BOX)
    low, high = heading.get_ylim()      # room below the data for the times
    ticks = [tick for tick in heading.get_yticks() if low <= tick <= high]
    heading.set_ylim(low - 0.4 * (high - low), high)
    heading.set_yticks(ticks)
    where = heading.get_xaxis_transform()
    for height, start, end, time, name, colour in (
            (0.03, 0, 1, zz.initial_turning_time, "initial turning", "tab:green"),
            (0.12, 1, None, zz.time_to_check_yaw, "check yaw", "tab:purple"),
            (0.21, 1, 3, zz.period, "period", "0.3")):
        if math.isnan(time):
            continue
        start = zz.executes[start]
        end = zz.overshoots[0].time if end is None else zz.executes[end]
        heading.annotate("", xy=(end, height), xytext=(start, height), xycoords=where,
                         arrowprops=dict(color=colour, **_BOTH_WAYS))
        heading.text(start, height + 0.015, f"{name} {time:.1f} s", transform=where,
                     ha="left", va="bottom", fontsize=7, color=colour)
    legend_if_any(heading)
    r.plot(t, np.degrees(run["ship.r"]), color="k")
    r.axhline(0.0, color="0.6", linewidth=0.6)
    text_panel(fig.add_subplot(grid[3, :]), lines)
    return fig


def _line(ax: Any, earth: Callable, start: tuple[float, float], end: tuple[float, float],
          **style: Any) -> tuple[tuple[float, float], tuple[float, float]]:
    """A line between two (along, across) points (dashed grey unless ``style``), its ends."""
    p, q = earth(*start), earth(*end)
    ax.plot([p[0], q[0]], [p[1], q[1]], **(style or dict(color="0.5", linewidth=0.6,
                                                          linestyle="--", zorder=5)))
    return p, q


def _dimension(ax: Any, earth: Callable, start: tuple[float, float], end: tuple[float, float],
               label: str, colour: str, label_at: tuple[float, float] | None = None,
               feet: tuple[tuple[float, float], ...] = ()) -> None:
    """A dimension line between (along, across) points, from ``feet``; gid its label's 1st word."""
    for foot, point in zip(feet, (start, end)):
        _line(ax, earth, foot, point)
    p, q = _line(ax, earth, start, end, color=colour, linewidth=1.6, zorder=6, gid=label.split()[0])
    ax.annotate("", xy=q, xytext=p, arrowprops=dict(arrowstyle="|-|", color=colour, shrinkA=0,
                                                    shrinkB=0, mutation_scale=6), zorder=6)
    middle = (0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]))
    ax.annotate(label, xy=middle, xytext=middle if label_at is None else earth(*label_at),
                fontsize=8, color=colour, ha="center", va="center", zorder=7, bbox=_ROUND,
                arrowprops=None if label_at is None else dict(arrowstyle="-", color=colour,
                                                              linewidth=0.7))


def turning_circle_plate(run: Recording, **_: Any) -> Figure:
    """Track with the diameters; heading, speed, drift, yaw rate and rudder; criteria."""
    tc = turning_circle_of(run).figures
    lines = turning_circle_report(run)
    fig, grid = text_grid((1.15, 1.0), 5, lines)
    track = fig.add_subplot(grid[0:5, 0])
    track_panel(track, run)
    L, x, y, psi = Hull.L, run["ship.x"], run["ship.y"], run["ship.psi"]
    along, across = approach_frame(x, y, float(psi[0]))
    earth = partial(to_earth, x[0], y[0], psi[0])
    side = math.copysign(1.0, across[np.argmax(np.abs(across))])     # the turn's side
    top, gap = along.max(), 0.08 * max(np.ptp(across), L)
    outside = -side * (max(-side * across.min(), -side * across.max(), 0.0) + gap)
    _line(track, earth, (-gap, 0.0), (top + 2 * gap, 0.0))
    track.annotate("approach course", earth(-gap, 0.0), fontsize=7, color="0.4",
                ha="center", va="top", bbox=_BOX, zorder=7)
    a90 = at_heading_change(psi, math.pi / 2, along, across)
    if not math.isnan(tc.advance):
        _dimension(track, earth, (0.0, outside), (tc.advance, outside),
                   f"advance\n{tc.advance:.2f} m\n{tc.advance / L:.2f} L", "tab:green",
                   feet=((0.0, 0.0), a90))
        _dimension(track, earth, (a90[0], 0.0), a90,
                   f"transfer {tc.transfer:.2f} m = {tc.transfer / L:.2f} L (at 90 deg)",
                   "tab:purple", label_at=(a90[0] - 1.5 * gap, side * 3.5 * gap))
    a180 = at_heading_change(psi, math.pi, along, across)
    if not math.isnan(tc.tactical_diameter):
        _dimension(track, earth, (top + gap, 0.0), (top + gap, a180[1]),
                   f"tactical diameter {tc.tactical_diameter:.2f} m = "
                   f"{tc.tactical_diameter / L:.2f} L (at 180 deg)", "tab:brown",
                   feet=((a180[0], 0.0), a180))
    north, east, diameter = steady_circle(x, y, psi)
    if not math.isnan(diameter):
        track.add_patch(Circle((east, north), diameter / 2, fill=False, linestyle="--",
                            color="tab:orange", linewidth=0.9, zorder=4))
        track.annotate("", xy=(east + diameter / 2, north), xytext=(east - diameter / 2, north),
                    arrowprops=dict(color="tab:orange", **_BOTH_WAYS), zorder=6)
        track.text(east, north, f"steady turning diameter {diameter:.2f} m = {diameter / L:.2f} L"
                f"\n(circle fitted to the last lap; 2U/|r| = {tc.diameter_from_rates:.2f} m)",
                ha="center", va="bottom", fontsize=7, color="tab:orange", zorder=7, bbox=_ROUND)
    heading, speed, drift, r, rudder = time_axes(fig, [grid[i, 1] for i in range(5)], (
        "heading psi\n(deg, 0-360)", "speed U (m/s)", "drift angle (deg)", "yaw rate r (deg/s)",
        "rudder -delta (deg,\n+ to starboard)"))
    t, u, v = run.t, run["ship.u"], run["ship.v"]
    compass = np.degrees(psi) % 360.0          # broken where it wraps
    compass[1:][np.abs(np.diff(compass)) > 180.0] = np.nan
    heading.plot(t, compass, color="k")
    heading.set(ylim=(0, 360), yticks=(0, 90, 180, 270, 360))
    scale = outlines(run).scale
    for target in (math.pi / 2, math.pi):       # the ship and the time at 90 and 180 deg
        xs, ys, ps, when = at_heading_change(psi, target, x, y, psi, t)
        if math.isnan(when):
            continue
        track.add_patch(Polygon(hull_outline(xs, ys, ps, scale), closed=True, facecolor="gold",
                                edgecolor="k", linewidth=0.8, zorder=4))
        track.annotate(f"{math.degrees(target):.0f} deg heading change", (ys, xs),
                       textcoords="offset points", xytext=(6, -12), fontsize=7, zorder=7)
        for panel in (heading, speed, drift, r, rudder):
            panel.axvline(when, color="tab:gray", linestyle=":", linewidth=0.9)
        heading.text(when, 1.0, f" {math.degrees(target):.0f} deg", va="bottom", fontsize=7,
                     transform=heading.get_xaxis_transform(), color="tab:gray")
    speed.plot(t, np.hypot(u, v), color="k")
    speed.axhline(tc.steady_speed, linestyle=":", color="tab:gray")
    drift.plot(t, np.degrees(np.arctan2(v, u)), color="k")
    r.plot(t, np.degrees(run["ship.r"]), color="k")
    r.axhline(math.degrees(tc.steady_yaw_rate), linestyle=":", color="tab:gray")
    _rudder(rudder, run)
    legend_if_any(rudder)
    text_panel(fig.add_subplot(grid[5, :]), lines)
    return fig
