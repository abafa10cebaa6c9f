"""The track panel every figure of a run shares: north up at equal scale, the named route,
leg switches, the ship's outline at regular times and the wave direction."""
from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Polygon
from matplotlib.path import Path as Shape

from autopilot_fmu.guidance import route as followed_route
from ship_fmu.data import Hull

from ..core.recording import Recording

OUTLINES = 12                   # ship outlines along a track, about
TRACK = "track"                 # a track panel's label, for legend_if_any
_DIRECTIONS = [(math.cos(a), math.sin(a)) for a in np.radians(np.arange(0, 360, 45))]


def waypoint_name(i: int) -> str:
    """Route point ``i`` (0-based) by name, from 'WP1' as Fossen (2011, ch. 10)."""
    return f"WP{i + 1}"


def to_earth(x: float, y: float, psi: float, along: Any, across: Any) -> tuple[Any, Any]:
    """(east, north) of points ``along`` and ``across`` (to starboard) of (x, y) heading psi."""
    c, s = math.cos(psi), math.sin(psi)
    return y + along * s + across * c, x + along * c - across * s


def hull_outline(x: float, y: float, psi: float, scale: float = 1.0) -> np.ndarray:
    """The ship's waterline as (east, north) corners at (x, y, psi), ``scale`` times enlarged."""
    L, B = scale * Hull.L, scale * Hull.B
    return np.column_stack(to_earth(x, y, psi, *np.array([
        (L / 2, 0.0), (L / 4, B / 2), (-L / 2, B / 2), (-L / 2, -B / 2), (L / 4, -B / 2)]).T))


def outline_scale(spacing: float, extent: float) -> int:
    """The largest factor 1 ... 9, 10, 20, ... keeping an outline within 0.8 spacing, extent/12."""
    limit = min(0.8 * spacing, extent / 12.0) / Hull.L
    if limit < 1.0:
        return 1
    decade = 10 ** math.floor(math.log10(limit))
    return int(limit // decade * decade)


@dataclass(frozen=True)
class Outlines:
    """Where a track shows the ship's outline: the rows, every how many s, how enlarged."""
    rows: list[int]
    every: float
    scale: int
    size: str                   # the enlargement in words


def outlines(run: Recording) -> Outlines:
    """About ``OUTLINES`` outlines at round times, none on top of an earlier one."""
    x, y, t = run["ship.x"], run["ship.y"], run.t
    every = max(1.0, round((t[-1] - t[0]) / OUTLINES / 10.0) * 10.0)
    stride = max(1, round(every / run.meta.get("step_size", t[1] - t[0])))
    rows = list(range(0, len(t), stride))
    steps = np.hypot(np.diff(x[rows]), np.diff(y[rows]))
    extent = max(np.ptp(x), np.ptp(y))
    scale = outline_scale(float(np.median(steps)) if len(steps) else extent, extent)
    drawn: list[int] = []
    for k in rows:
        if all(math.hypot(x[k] - x[j], y[k] - y[j]) > scale * Hull.L for j in drawn):
            drawn.append(k)
    return Outlines(drawn, every, scale, "to scale" if scale == 1 else f"x{scale}, true heading")


def _arrow(direction: float) -> Shape:
    east, north = np.array([(0, 1), (0.5, 0.15), (0.17, 0.15), (0.17, -1), (-0.17, -1),
                            (-0.17, 0.15), (-0.5, 0.15), (0, 1)]).T
    return Shape(np.column_stack(to_earth(0.0, 0.0, direction, north, east)), closed=True)


def _route(ax: Any, guidance: dict[str, Any], tracks: list[np.ndarray]) -> None:
    """The route, framed on the tracks and the points near them; the others named in the legend."""
    points = np.array(followed_route(guidance))[:, ::-1]              # (east, north)
    reach = guidance["R_accept"]
    seen = np.concatenate(tracks)
    low, high = seen.min(axis=0), seen.max(axis=0)
    gap = np.linalg.norm(np.maximum(0.0, np.maximum(low - points, points - high)), axis=1)
    near = gap <= max(*(high - low), 4 * Hull.L) / 2
    label = "route"
    if not near.all():
        last = int(np.flatnonzero(~near)[-1])
        label += (f", continuing out of view to {waypoint_name(last)} "
                  f"({points[last][1]:g}, {points[last][0]:g}) m")
    # add_artist leaves the data limits (the frame) alone: the points in view set them.
    ax.add_artist(Line2D(points[:, 0], points[:, 1], linestyle="--", marker="o",
                         color="tab:blue", linewidth=0.8, markersize=4, label=label,
                         zorder=2))
    for east, north in points[1:]:
        ax.add_artist(Circle((east, north), reach, fill=False, linestyle=":",
                             color="tab:blue", zorder=2))
    framed = np.concatenate([*tracks, points[near] - reach, points[near] + reach])
    ax.update_datalim(framed)
    size = float(np.ptp(framed, axis=0).max())
    steps = np.linspace(0.0, 1.0, 40, endpoint=False)[:, None]
    avoid = np.concatenate([*(t[::10] for t in tracks),                # the tracks and legs
                            *(a + steps * (b - a) for a, b in itertools.pairwise(points)),
                            points[-1:]])
    for i, point in enumerate(points):          # each name on the side farthest from them
        away = np.array(max(_DIRECTIONS, key=lambda d: np.min(np.hypot(
            *(avoid - (point + np.array(d) * (reach + 0.04 * size))).T))))
        ax.annotate(waypoint_name(i), tuple(point), xytext=tuple(point + away * reach * 1.1),
                    textcoords="data", fontsize=8, fontweight="bold", color="tab:blue",
                    ha="left" if away[0] > 0.3 else "right" if away[0] < -0.3 else "center",
                    va="bottom" if away[1] > 0.3 else "top" if away[1] < -0.3 else "center",
                    zorder=5)


def track_panel(ax: Any, run: Recording, ship: bool = True,
                others: Iterable[Recording] = ()) -> None:
    """Route, waves and, with ``ship``, the track; framed on ``others`` too (the caller's)."""
    p = run.meta.get("parameters", {})
    x, y, psi = run["ship.x"], run["ship.y"], run["ship.psi"]
    tracks = [np.column_stack([r["ship.y"], r["ship.x"]]) for r in (run, *others)]
    ax.set_label(TRACK)
    if ship:
        ax.plot(y, x, color="k", linewidth=1.0, label="track", zorder=3)
    if "guidance" in p:
        _route(ax, p["guidance"], tracks)
        if ship:
            switched = np.flatnonzero(np.diff(run["guidance.wp_index"])) + 1
            ax.plot(y[switched], x[switched], "x", color="tab:red", markersize=8, mew=2,
                    label="leg switched", zorder=4)
    if ship:
        shown = outlines(run)
        for k in shown.rows:
            ax.add_patch(Polygon(hull_outline(x[k], y[k], psi[k], shown.scale), closed=True,
                                 facecolor="0.8", edgecolor="0.3", linewidth=0.6, zorder=2.5))
        ax.plot([], [], "s", color="0.8", markeredgecolor="0.3",
                label=f"ship outline {shown.size}, every {shown.every:g} s")
        for flow, color, what in (("c", "tab:blue", "current"), ("w", "tab:olive", "wind")):
            if f"environment.V_{flow}" in run.columns and run[f"environment.V_{flow}"].any():
                k = shown.rows                  # where the current (wind) was, and how strong
                V, beta = run[f"environment.V_{flow}"][k], run[f"environment.beta_{flow}"][k]
                ax.quiver(y[k], x[k], V * np.sin(beta), V * np.cos(beta), color=color,
                          angles="xy", zorder=4, label=f"{what}, up to {V.max():.3g} m/s")
    sea = p.get("ship", {})
    if sea.get("Hs", 0.0) > 0.0:
        ax.plot([], [], linestyle="none", marker=_arrow(sea["psi_w"]), markersize=11,
                color="tab:cyan", label=f"waves travel to "
                f"{math.degrees(sea['psi_w']) % 360:.0f} deg")
    ax.set(xlabel="east y (m)", ylabel="north x (m)")
    ax.set_aspect("equal", adjustable="datalim")
    legend_if_any(ax)


def legend_if_any(ax: Any) -> None:
    """A legend over no data: a track panel's below the panels, others' above their axes."""
    handles, labels = ax.get_legend_handles_labels()
    if handles and ax.get_label() == TRACK:
        ax.figure.legends.clear()                   # a track panel's legend, redrawn
        ax.figure.legend(handles, labels, loc="outside lower left", fontsize=7,
                         ncol=min(3, len(handles)), handleheight=1.8)
    elif handles:
        ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=7, ncol=len(handles),
                  frameon=False, borderaxespad=0.1)
