"""Figures of a sweep and of the scorecard: each criterion per controller and sea state, the
paired changes, the tracks and the J_SMC / J_PD map; drawn without pyplot (no backend)."""
from __future__ import annotations

import math
import textwrap
from pathlib import Path
from typing import Sequence

import matplotlib
import matplotlib.ticker
import matplotlib.transforms
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from autopilot_fmu.guidance import parse_waypoints

from ..analysis.figures import save
from ..analysis.seastate import model_scale
from ..analysis.track import waypoint_name
from .merit import CRITERIA, Merit
from .sweep_tables import distinct, select

STATISTICS = ("box: median and IQR (25-75 %) of the runs, whiskers: min-max; the number "
              "under each box: its median")         # what each box of ``distribution`` shows


def _panels(count: int, width: float, height: float) -> tuple[Figure, list]:
    columns = min(4, count)
    rows = math.ceil(count / columns)
    fig = Figure(figsize=(width * columns, height * rows), layout="constrained")
    axes = fig.subplots(rows, columns, squeeze=False).flat
    for ax in axes[count:]:
        ax.set_visible(False)
    return fig, axes[:count]


def distribution(spec, rows: list[dict], path: Path,
                 criteria: Sequence[Merit] = CRITERIA[:1]) -> Path:
    """Box plots of each criterion (J alone by default) per controller and sea state, one
    panel each, on a log scale where it spans decades; each run counted once."""
    ok = [r for r in distinct(rows) if r["status"] == "ok"]
    sea = next((a for a in ("sea_state", "Hs") if a in spec.axes), None)
    groups = spec.axes[sea] if sea else [None]
    width = max(6.0 if len(criteria) == 1 else 3.4, 0.75 * len(groups) * len(spec.controllers)
                + 1.2)
    step = len(spec.controllers) + 1
    fig, axes = _panels(len(criteria), width, 3.9)
    for ax, criterion in zip(axes, criteria):       # a panel each
        positions, data, labels = [], [], []
        for g, group in enumerate(groups):
            for c, controller in enumerate(spec.controllers):
                values = [r[criterion.column]
                          for r in select(ok, controller, {sea: group} if sea else {})]
                positions.append(g * step + c)
                data.append([v for v in values if np.isfinite(v)] or [np.nan])
                labels.append(f"{controller}\n{criterion.format(float(np.median(data[-1])))}")
        ax.boxplot(data, positions=positions, widths=0.7, whis=(0, 100), showfliers=False)
        ax.set_xticks(positions, labels, fontsize=7)
        below = matplotlib.transforms.blended_transform_factory(ax.transData, ax.transAxes)
        for g, group in enumerate(groups if len(groups) > 1 else []):  # a name under its boxes
            ax.text(g * step + (step - 2) / 2, -0.2, f"{sea} {group}", transform=below,
                    ha="center", va="top", fontsize=8, fontweight="bold")
        values = [v for d in data for v in d if np.isfinite(v)]
        unit = f" ({criterion.unit})" if criterion.unit else ""
        if not values:
            ax.text(0.5, 0.5, "no run succeeded", transform=ax.transAxes, ha="center")
        elif min(values) > 0 and max(values) > 10 * min(values):
            ax.set_yscale("log")            # the values span decades
            unit = f" ({criterion.unit}, log scale)" if criterion.unit else " (log scale)"
        elif criterion.out_of:              # a count: from 0 to the most there are
            total = max(r[criterion.out_of] for r in ok)
            ax.set_ylim(-0.2, total + 0.2)
            ax.set_yticks(range(int(total) + 1))
            unit = f" (of {total:.0f})"
        elif min(values) == max(values):    # all alike: an axis about them, from 0 if 0
            ax.set_ylim(-0.05 if values[0] == 0 else values[0] - 1, values[0] + 1)
        ax.set_xlim(min(positions) - 0.6, max(positions) + 0.6)
        _labels(ax, criterion, criterion.label + unit)
    what = "J" if len(criteria) == 1 else "each criterion"
    at = (f" and {sea}" if len(groups) > 1 else f", {sea} {groups[0]}") if sea else ""
    caption = textwrap.fill(STATISTICS, int(12 * width * min(4, len(criteria))))  # 9 pt: ~12/in
    fig.suptitle(f"{spec.name}: {what} per controller{at}\n{caption}", fontsize=9)
    return save(fig, path)[0]


def _labels(ax, criterion: Merit, ylabel: str) -> None:
    ax.set_ylabel(ylabel, fontsize=8)
    ax.set_title(f"{criterion.label}: {criterion.better}", fontsize=9)
    ax.grid(alpha=0.3, axis="y")


def paired_figure(title: str, changes: dict[Merit, dict[str, np.ndarray]], baseline: str,
                  path: Path) -> Path:
    """Each criterion's paired ratios (log scale) or differences of every controller to
    ``baseline``: a dot per seed, a bar at their median, the better side shaded."""
    fig, axes = _panels(len(changes), 3.6, 3.6)
    for ax, (criterion, by_controller) in zip(axes, changes.items()):     # a panel each
        ratio = criterion.paired == "ratio"
        reference = 1.0 if ratio else 0.0
        values = np.concatenate([*by_controller.values(), np.array([])])
        values = values[np.isfinite(values) & ((values > 0) if ratio else True)]
        for i, (controller, change) in enumerate(by_controller.items()):
            jitter = np.linspace(-0.18, 0.18, change.size) if change.size > 1 else np.zeros(1)
            ax.plot(i + jitter[:change.size], change, "o", markersize=3, alpha=0.6, color=f"C{i}")
            if np.isfinite(change).any():
                median = float(np.nanmedian(change))
                ax.plot([i - 0.3, i + 0.3], [median, median], color="k", linewidth=1.5)
                ax.annotate(f"{median:.2f}" if ratio else criterion.format(median, "+"),
                            (i + 0.32, median), fontsize=7, va="center")
        ax.axhline(reference, color="0.3", linewidth=0.8)
        # symmetric about 1 in log (x2 as far as /2) or about 0, never flat
        span = 1.15 * max(float(np.abs(np.log(values) if ratio else values).max())
                          if values.size else 0.0,
                          math.log(1.1) if ratio else 10.0 ** -criterion.digits)
        low, high = (math.exp(-span), math.exp(span)) if ratio else (-span, span)
        if ratio:
            ax.set_yscale("log")
            ax.set_yticks([float(f"{t:.2g}") for t in np.exp(np.linspace(-span, span, 7)[1:-1])])
            ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            ax.yaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        ax.set_ylim(low, high)
        ax.axhspan(*((low, reference) if criterion.lower_is_better else (reference, high)),
                   color="tab:green", alpha=0.08)
        ax.set_xticks(range(len(by_controller)), list(by_controller), fontsize=7)
        ax.set_xlim(-0.6, len(by_controller) - 0.2)
        unit = f", {criterion.unit}" if criterion.unit else ""
        _labels(ax, criterion, f"ratio to the {baseline} (log scale)" if ratio
                else f"difference from the {baseline}{unit}")
    fig.suptitle(f"{title}: each controller against the {baseline} on the same sea, "
                 "one dot per wave seed, bar: median; shaded: better", fontsize=9)
    return save(fig, path)[0]


def ratio_map(spec, rows: list[dict], path: Path, numerator: str) -> Path | None:
    """Mean J of ``numerator`` over the PD's, over the two map axes (other axes pooled)."""
    denominator = "pd"
    if len(spec.map_axes) != 2 or not {numerator, denominator} <= set(spec.controllers):
        return None
    x_axis, y_axis = spec.map_axes
    xs, ys = spec.axes[x_axis], spec.axes[y_axis]
    ok = [r for r in rows if r["status"] == "ok"]
    mean_J = {c: np.array([[np.mean([r["J"] for r in select(ok, c, {x_axis: x, y_axis: y})]
                                    or [np.nan]) for x in xs] for y in ys])
              for c in (numerator, denominator)}
    ratio = mean_J[numerator] / mean_J[denominator]
    fig = Figure(figsize=(6.5, 4.5), layout="constrained")
    ax = fig.subplots()
    image = ax.imshow(np.log2(ratio), cmap="RdBu_r", vmin=-3, vmax=3, origin="lower",
                      aspect="auto")
    for (i, j), value in np.ndenumerate(ratio):
        ax.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=8)
    ax.set_xticks(range(len(xs)), [str(x) for x in xs], fontsize=8)
    ax.set_yticks(range(len(ys)), [str(y) for y in ys], fontsize=8)
    ax.set(xlabel=x_axis, ylabel=y_axis)
    fig.colorbar(image, label=f"log2(J_{numerator} / J_{denominator})")
    ax.set_title(f"{spec.name}: J_{numerator} / J_{denominator} (< 1: {numerator} better)",
                 fontsize=10)
    return save(fig, path)[0]


def tracks(spec, rows: list[dict], path: Path) -> Path | None:
    """The tracks of the runs [plots] tracks selects, one colour per controller, the route."""
    chosen = [r for r in rows if r.get("track")]
    if not chosen:
        return None
    fig = Figure(figsize=(6.5, 7), layout="constrained")
    ax = fig.subplots()
    for controller, color in zip(spec.controllers, matplotlib.rcParams["axes.prop_cycle"].by_key()
                                 ["color"]):
        mine = [r["track"] for r in chosen if r["controller"] == controller]
        for i, track in enumerate(mine):
            ax.plot(track["y"], track["x"], color=color, linewidth=0.8, alpha=0.45,
                    label=f"{controller} ({len(mine)} runs)" if i == 0 else None)
    route, R_accept = chosen[0]["track"].get("route"), chosen[0]["track"].get("R_accept")
    if route:
        points = np.array(parse_waypoints(route) if isinstance(route, str) else route)
        ax.plot(points[:, 1], points[:, 0], "--o", color="0.3", linewidth=0.8, markersize=3,
                label="route" + (f", circles of acceptance {R_accept:g} m" if R_accept else ""))
        for k, (x, y) in enumerate(points):
            ax.annotate(waypoint_name(k), (y, x), xytext=(4, 4), textcoords="offset points",
                        fontsize=8, color="0.2")
            if R_accept:
                ax.add_patch(Circle((y, x), R_accept, fill=False, linestyle=":", color="0.3",
                                    linewidth=0.8))
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
    """A sweep's figures: J's distribution, the tracks, each controller's map against the PD."""
    written = [distribution(spec, rows, out / "J_distribution.png"),
               tracks(spec, rows, out / "tracks.png"),
               *(ratio_map(spec, rows, out / f"J_{c}_over_pd.png", c)
                 for c in spec.controllers if c != "pd")]
    return [path for path in written if path is not None]
