"""IMO-style plates of a zig-zag and a turning circle (MSC/Circ.1053) with the MSC.137(76)
criteria, their words from ``reports``: plate and report cannot disagree. The rudder is drawn
as -delta, the heading's sign sense (a positive delta turns this ship to port)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from ..core.recording import Recording
from .figures import text_grid, text_panel, time_axes
from .criteria import Assessment, turning_circle_of, zigzag_of
from .manoeuvres import (TurningCircle, ZigZagResult, approach_frame, at_heading_change,
                         steady_circle)
from .reports import turning_circle_lines, zigzag_lines
from .track import hull_outline, legend_if_any, outlines, track_panel

RUDDER = "rudder -delta (deg, + turns to starboard)"
_ORDINALS = ("1st", "2nd", "3rd", "4th")
_BOX = dict(boxstyle="round,pad=0.15", facecolor="white", alpha=0.85, edgecolor="none")
_ROUND = {**_BOX, "boxstyle": "round"}


def _rudder(ax: Any, run: Recording) -> None:
    ax.plot(run.t, -np.degrees(run["ship.delta_c"]), "--", color="tab:blue", linewidth=0.7,
            label="rudder ordered")
    ax.plot(run.t, -np.degrees(run["ship.delta"]), color="tab:blue", linewidth=1.2,
            label="rudder")


def _span(ax: Any, start: float, end: float, height: float, label: str, colour: str) -> None:
    where = ax.get_xaxis_transform()
    ax.annotate("", xy=(end, height), xytext=(start, height), xycoords=where,
                arrowprops=dict(arrowstyle="<->", color=colour, shrinkA=0, shrinkB=0))
    ax.text(start, height + 0.015, label, transform=where, ha="left", va="bottom",
            fontsize=7, color=colour)


def _executes(ax: Any, run: Recording, zz: ZigZagResult) -> None:
    rows = np.searchsorted(run.t, zz.executes)
    psi = np.degrees(run["ship.psi"][rows])
    ax.plot(zz.executes, psi, "o", color="tab:red", markersize=4, zorder=5,
            label="execute (rudder ordered)")
    for name, t, heading in zip(_ORDINALS, zz.executes, psi):
        ax.annotate(f"{name} execute", (t, heading), textcoords="offset points",
                    xytext=(4, -10 if heading <= 0 else 4), fontsize=7, color="tab:red")


def _overshoots(ax: Any, zz: ZigZagResult) -> None:
    switch = math.degrees(zz.psi_switch)
    for n, o in enumerate(zz.overshoots):
        peak = math.degrees(o.heading)
        ax.annotate("", xy=(o.time, peak), xytext=(o.time, math.copysign(switch, peak)),
                    arrowprops=dict(arrowstyle="<->", color="tab:purple", shrinkA=0,
                                    shrinkB=0))
        if n < 2:
            ax.annotate(f"{_ORDINALS[n]} overshoot {math.degrees(o.angle):.1f} deg",
                        (o.time, peak), textcoords="offset points",
                        xytext=(5, -9 if peak < 0 else 3), fontsize=7, color="tab:purple",
                        bbox=_BOX)


def _spans(ax: Any, zz: ZigZagResult) -> None:
    low, high = ax.get_ylim()
    ticks = [tick for tick in ax.get_yticks() if low <= tick <= high]
    ax.set_ylim(low - 0.4 * (high - low), high)
    ax.set_yticks(ticks)
    if len(zz.executes) > 1:
        _span(ax, zz.executes[0], zz.executes[1], 0.03,
              f"initial turning {zz.initial_turning_time:.1f} s", "tab:green")
    if zz.overshoots:
        _span(ax, zz.executes[1], zz.overshoots[0].time, 0.12,
              f"check yaw {zz.time_to_check_yaw:.1f} s", "tab:purple")
    if not math.isnan(zz.period):
        _span(ax, zz.executes[1], zz.executes[3], 0.21, f"period {zz.period:.1f} s", "0.3")


def _runaway(ax: Any, run: Recording, zz: ZigZagResult, a: Assessment) -> None:
    limit = 6.0 * max(math.degrees(zz.psi_switch), math.degrees(a.delta))
    ax.set_ylim(-limit, limit)
    psi = np.degrees(run["ship.psi"])
    gone = int(np.argmax(np.abs(psi) > limit)) if np.abs(psi).max() > limit else len(psi) - 1
    ax.set_xlim(run.t[0], min(run.t[-1], run.t[0] + 4.0 * (run.t[gone] - run.t[0])))
    side = math.copysign(1.0, psi[-1])
    ax.annotate(f"heading {psi[-1]:.0f} deg at t = {run.t[-1]:.0f} s, still going away: the "
                "turn was not checked within the run", xy=(run.t[gone], side * limit),
                xytext=(run.t[0] + 1.15 * (run.t[gone] - run.t[0]), side * 0.75 * limit),
                fontsize=8, color="tab:red", arrowprops=dict(arrowstyle="->", color="tab:red"))


def _zoom(ax: Any, run: Recording, zz: ZigZagResult) -> None:
    if len(zz.executes) < 6:
        return
    end = zz.executes[5] + 0.25 * (zz.executes[5] - zz.executes[4])
    shown = run.t <= end
    psi = np.degrees(run["ship.psi"][shown])
    rudder = math.degrees(np.abs(run["ship.delta"]).max())
    margin = 0.1 * (psi.max() - psi.min())
    ax.set_xlim(run.t[0], end)
    ax.set_ylim(min(psi.min(), -rudder) - margin, max(psi.max(), rudder) + margin)
    ax.text(0.99, 0.99, f"first {end - run.t[0]:.0f} s of {run.t[-1] - run.t[0]:.0f} s; the "
            "track shows all", transform=ax.transAxes, ha="right", va="top", fontsize=7,
            color="0.4", bbox=_BOX)


def zigzag_plate(run: Recording, **_: Any) -> Figure:
    """Heading and rudder with executes, overshoots and times; yaw rate; track; criteria."""
    a = zigzag_of(run)
    zz = a.figures
    lines = zigzag_lines(a, run)
    fig, grid = text_grid((2.2, 1.0), 3, lines)
    heading, r = time_axes(fig, [grid[0:2, 0], grid[2, 0]])
    track_panel(fig.add_subplot(grid[0:3, 1]), run)
    heading.plot(run.t, np.degrees(run["ship.psi"]), color="k", linewidth=1.4,
                 label="heading psi")
    _rudder(heading, run)
    heading.axhline(0.0, color="0.6", linewidth=0.6)
    for level in (-math.degrees(zz.psi_switch), math.degrees(zz.psi_switch)):
        heading.axhline(level, linestyle=":", color="0.4", linewidth=0.9)     # rudder reverses
        heading.text(1.0, level, f" {level:+g}", transform=heading.get_yaxis_transform(),
                     va="center", fontsize=7, color="0.4")
    _executes(heading, run, zz)
    _overshoots(heading, zz)
    if zz.running is not None:
        _runaway(heading, run, zz, a)
    else:
        _zoom(heading, run, zz)
    _spans(heading, zz)
    heading.set_ylabel(f"heading psi, {RUDDER}")
    legend_if_any(heading)
    r.plot(run.t, np.degrees(run["ship.r"]), color="k")
    r.axhline(0.0, color="0.6", linewidth=0.6)
    r.set_ylabel("yaw rate r (deg/s)")
    text_panel(fig.add_subplot(grid[3, :]), lines)
    return fig


def _earth(run: Recording, along: float, across: float) -> tuple[float, float]:
    """(east, north) of a point along and across (to starboard of) the approach course."""
    x0, y0, psi0 = run["ship.x"][0], run["ship.y"][0], run["ship.psi"][0]
    c, s = math.cos(psi0), math.sin(psi0)
    return y0 + along * s + across * c, x0 + along * c - across * s


def _dimension(ax: Any, run: Recording, start: tuple[float, float], end: tuple[float, float],
               label: str, colour: str, label_at: tuple[float, float] | None = None) -> None:
    """A dimension line between two (along, across) points; its gid the label's first word."""
    p, q = _earth(run, *start), _earth(run, *end)
    ax.plot([p[0], q[0]], [p[1], q[1]], color=colour, linewidth=1.6, zorder=6,
            gid=label.split()[0])
    ax.annotate("", xy=q, xytext=p, arrowprops=dict(arrowstyle="|-|", color=colour,
                                                    shrinkA=0, shrinkB=0,
                                                    mutation_scale=6), zorder=6)
    middle = (0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]))
    where = middle if label_at is None else _earth(run, *label_at)
    ax.annotate(label, xy=middle, xytext=where, fontsize=8, color=colour, ha="center",
                va="center", zorder=7, bbox=_ROUND,
                arrowprops=None if label_at is None else dict(arrowstyle="-", color=colour,
                                                              linewidth=0.7))


def _extension(ax: Any, run: Recording, start: tuple[float, float],
               end: tuple[float, float]) -> None:
    p, q = _earth(run, *start), _earth(run, *end)
    ax.plot([p[0], q[0]], [p[1], q[1]], color="0.5", linewidth=0.6, linestyle="--", zorder=5)


def _turning_track(ax: Any, run: Recording, a: Assessment) -> None:
    """The track dimensioned: advance, transfer, tactical and steady diameters."""
    track_panel(ax, run)
    tc, L = a.figures, a.length
    x, y, psi = run["ship.x"], run["ship.y"], run["ship.psi"]
    along, across = approach_frame(x, y, float(psi[0]))
    side = math.copysign(1.0, across[np.argmax(np.abs(across))])     # the turn's side
    top, gap = along.max(), 0.08 * max(np.ptp(across), L)
    outside = -side * (max(-side * across.min(), -side * across.max(), 0.0) + gap)
    _extension(ax, run, (-gap, 0.0), (top + 2 * gap, 0.0))
    ax.annotate("approach course", _earth(run, -gap, 0.0), fontsize=7, color="0.4",
                ha="center", va="top", bbox=_BOX, zorder=7)
    a90 = tuple(at_heading_change(psi, math.pi / 2, along, across))
    if not math.isnan(tc.advance):
        _extension(ax, run, (0.0, 0.0), (0.0, outside))
        _extension(ax, run, a90, (a90[0], outside))
        _dimension(ax, run, (0.0, outside), (tc.advance, outside),
                   f"advance\n{tc.advance:.2f} m\n{tc.advance / L:.2f} L", "tab:green")
        _dimension(ax, run, (a90[0], 0.0), a90,
                   f"transfer {tc.transfer:.2f} m = {tc.transfer / L:.2f} L (at 90 deg)",
                   "tab:purple", label_at=(a90[0] - 1.5 * gap, side * 3.5 * gap))
    a180 = tuple(at_heading_change(psi, math.pi, along, across))
    if not math.isnan(tc.tactical_diameter):
        level = top + gap
        _extension(ax, run, (a180[0], 0.0), (level, 0.0))
        _extension(ax, run, a180, (level, a180[1]))
        _dimension(ax, run, (level, 0.0), (level, a180[1]),
                   f"tactical diameter {tc.tactical_diameter:.2f} m = "
                   f"{tc.tactical_diameter / L:.2f} L (at 180 deg)", "tab:brown")
    _steady(ax, run, tc, L)
    scale = outlines(run).scale          # the ship where its heading changed 90 and 180 deg
    for target in (math.pi / 2, math.pi):
        xs, ys, ps = at_heading_change(psi, target, x, y, psi)
        if math.isnan(xs):
            continue
        ax.add_patch(Polygon(hull_outline(xs, ys, ps, scale), closed=True, facecolor="gold",
                             edgecolor="k", linewidth=0.8, zorder=4))
        ax.annotate(f"{math.degrees(target):.0f} deg heading change", (ys, xs),
                    textcoords="offset points", xytext=(6, -12), fontsize=7, zorder=7)


def _steady(ax: Any, run: Recording, tc: TurningCircle, L: float) -> None:
    centre_x, centre_y, diameter = steady_circle(run["ship.x"], run["ship.y"], run["ship.psi"])
    if math.isnan(diameter):
        return
    ax.add_patch(Circle((centre_y, centre_x), diameter / 2, fill=False, linestyle="--",
                            color="tab:orange", linewidth=0.9, zorder=4))
    east = (centre_y - diameter / 2, centre_y + diameter / 2)
    ax.annotate("", xy=(east[1], centre_x), xytext=(east[0], centre_x),
                arrowprops=dict(arrowstyle="<->", color="tab:orange", shrinkA=0, shrinkB=0),
                zorder=6)
    ax.text(centre_y, centre_x, f"steady turning diameter {diameter:.2f} m = "
            f"{diameter / L:.2f} L\n(circle fitted to the last lap; 2U/|r| = "
            f"{tc.diameter_from_rates:.2f} m)", ha="center", va="bottom", fontsize=7,
            color="tab:orange", zorder=7, bbox=_ROUND)


def turning_circle_plate(run: Recording, **_: Any) -> Figure:
    """Track with the diameters; heading, speed, drift, yaw rate and rudder; criteria."""
    a = turning_circle_of(run)
    tc: TurningCircle = a.figures
    lines = turning_circle_lines(a)
    fig, grid = text_grid((1.15, 1.0), 5, lines)
    _turning_track(fig.add_subplot(grid[0:5, 0]), run, a)
    heading, speed, drift, r, rudder = time_axes(fig, [grid[i, 1] for i in range(5)])
    t, u, v = run.t, run["ship.u"], run["ship.v"]
    compass = np.degrees(run["ship.psi"]) % 360.0          # broken where it wraps
    compass[1:][np.abs(np.diff(compass)) > 180.0] = np.nan
    heading.plot(t, compass, color="k")
    heading.set(ylim=(0, 360), yticks=(0, 90, 180, 270, 360), ylabel="heading psi\n(deg, 0-360)")
    for target in (math.pi / 2, math.pi):
        when, = at_heading_change(run["ship.psi"], target, t)
        if math.isnan(when):
            continue
        for panel in (heading, speed, drift, r, rudder):
            panel.axvline(when, color="tab:gray", linestyle=":", linewidth=0.9)
        heading.text(when, 1.0, f" {math.degrees(target):.0f} deg", va="bottom", fontsize=7,
                     transform=heading.get_xaxis_transform(), color="tab:gray")
    speed.plot(t, np.hypot(u, v), color="k")
    speed.axhline(tc.steady_speed, linestyle=":", color="tab:gray")
    speed.set_ylabel("speed U (m/s)")
    drift.plot(t, np.degrees(np.arctan2(v, u)), color="k")
    drift.set_ylabel("drift angle (deg)")
    r.plot(t, np.degrees(run["ship.r"]), color="k")
    r.axhline(math.degrees(tc.steady_yaw_rate), linestyle=":", color="tab:gray")
    r.set_ylabel("yaw rate r (deg/s)")
    _rudder(rudder, run)
    rudder.set_ylabel("rudder -delta (deg,\n+ to starboard)")
    legend_if_any(rudder)
    text_panel(fig.add_subplot(grid[5, :]), lines)
    return fig
