"""Figures of a sweep: J per controller and sea state, and the J_SMC / J_PD map; each file
written whole or not at all (``cosim.analysis.figures.save``)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from autopilot_fmu.guidance import parse_waypoints  # noqa: E402

from ..analysis.figures import save  # noqa: E402
from ..analysis.seastate import model_scale  # noqa: E402

SEA_AXES = ("sea_state", "Hs")


def _sea_axis(spec) -> str | None:
    return next((a for a in SEA_AXES if a in spec.axes), None)


def distribution(spec, rows: list[dict], path: Path) -> Path:
    """Box plot of J per controller, grouped by sea state when that is an axis."""
    ok = [r for r in rows if r["status"] == "ok"]
    sea = _sea_axis(spec)
    groups = spec.axes[sea] if sea else [None]
    fig, ax = plt.subplots(figsize=(max(6, 1.6 * len(groups) * len(spec.controllers)), 4.5),
                           constrained_layout=True)
    positions, data, labels = [], [], []
    for g, group in enumerate(groups):
        for c, controller in enumerate(spec.controllers):
            J = [r["J"] for r in ok if r["controller"] == controller
                 and (sea is None or r[sea] == group)]
            positions.append(g * (len(spec.controllers) + 1) + c)
            data.append(J if J else [np.nan])
            labels.append(f"{controller}\n{sea} {group}" if sea else controller)
    ax.boxplot(data, positions=positions, widths=0.7)
    ax.set_xticks(positions, labels, fontsize=8)
    values = [j for J in data for j in J if np.isfinite(j)]
    if not values:
        ax.text(0.5, 0.5, "no run succeeded", transform=ax.transAxes, ha="center")
    elif min(values) > 0 and max(values) > 10 * min(values):
        ax.set_yscale("log")            # J spans decades across sea states and controllers
    ax.set_ylabel("J of eq (19) (rad^2)")
    ax.set_title(f"{spec.name}: J per controller" + (f" and {sea}" if sea else ""), fontsize=10)
    ax.grid(alpha=0.3, axis="y")
    return save(fig, path)[0]


def ratio_map(spec, rows: list[dict], path: Path, numerator: str = "smc",
              denominator: str = "pd") -> Path | None:
    """Mean J of one controller over the other's, over the two map axes (other axes pooled)."""
    if len(spec.map_axes) != 2 or not {numerator, denominator} <= set(spec.controllers):
        return None
    x_axis, y_axis = spec.map_axes
    xs, ys = spec.axes[x_axis], spec.axes[y_axis]
    ratio = np.full((len(ys), len(xs)), np.nan)
    for i, y in enumerate(ys):
        for j, x in enumerate(xs):
            means = []
            for controller in (numerator, denominator):
                J = [r["J"] for r in rows if r["status"] == "ok" and r["controller"] == controller
                     and r[x_axis] == x and r[y_axis] == y]
                means.append(np.mean(J) if J else np.nan)
            ratio[i, j] = means[0] / means[1]
    fig, ax = plt.subplots(figsize=(6.5, 4.5), constrained_layout=True)
    image = ax.imshow(np.log2(ratio), cmap="RdBu_r", vmin=-3, vmax=3, origin="lower",
                      aspect="auto")
    for i in range(len(ys)):
        for j in range(len(xs)):
            ax.text(j, i, f"{ratio[i, j]:.2f}", ha="center", va="center", fontsize=8)
    ax.set_xticks(range(len(xs)), [str(x) for x in xs], fontsize=8)
    ax.set_yticks(range(len(ys)), [str(y) for y in ys], fontsize=8)
    ax.set_xlabel(x_axis)
    ax.set_ylabel(y_axis)
    fig.colorbar(image, label=f"log2(J_{numerator} / J_{denominator})")
    ax.set_title(f"{spec.name}: J_{numerator} / J_{denominator} (< 1: {numerator} better)",
                 fontsize=10)
    return save(fig, path)[0]


def tracks(spec, rows: list[dict], path: Path) -> Path | None:
    """The tracks of the runs [plots] tracks selects, overlaid, one colour per controller:
    every run a thin line, so the spread over seeds shows; the route dashed."""
    chosen = [r for r in rows if r.get("track")]
    if not chosen:
        return None
    fig, ax = plt.subplots(figsize=(6.5, 7), constrained_layout=True)
    for controller, color in zip(spec.controllers, plt.rcParams["axes.prop_cycle"].by_key()
                                 ["color"]):
        mine = [r["track"] for r in chosen if r["controller"] == controller]
        for i, track in enumerate(mine):
            ax.plot(track["y"], track["x"], color=color, linewidth=0.8, alpha=0.45,
                    label=f"{controller} ({len(mine)} runs)" if i == 0 else None)
    route = chosen[0]["track"].get("route")
    if route:
        # a str: a row journaled before routes were recorded as points
        points = np.array(parse_waypoints(route) if isinstance(route, str) else route)
        ax.plot(points[:, 1], points[:, 0], "--o", color="0.3", linewidth=0.8, markersize=3,
                label="route")
    ax.set(xlabel="east y (m)", ylabel="north x (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    where = ", ".join(f"{k} {v}" for k, v in spec.tracks.items()) or "every run"
    if "sea_state" in spec.tracks:
        Hs, T0 = model_scale(spec.tracks["sea_state"])
        where += f" (Hs {Hs * 1000:.3g} mm, T0 {T0:.2g} s)"
    ax.set_title(f"{spec.name}: tracks ({where})", fontsize=10)
    return save(fig, path)[0]


def save_figures(spec, rows: list[dict], out: Path) -> list[Path]:
    written = [distribution(spec, rows, out / "J_distribution.png")]
    overlay = tracks(spec, rows, out / "tracks.png")
    if overlay is not None:
        written.append(overlay)
    for numerator in [c for c in spec.controllers if c != "pd"]:
        path = ratio_map(spec, rows, out / f"J_{numerator}_over_pd.png", numerator)
        if path is not None:
            written.append(path)
    return written
