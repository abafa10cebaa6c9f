"""What ``cosim.train`` shows: the learning curve, and the policy's J beside the PD's on
seeds training never saw."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ..analysis.figures import new_figure
from .cem import Curve, average


def learning_figure(curve: Curve, pd_mean: float, title: str) -> Figure:
    fig = new_figure(figsize=(7, 4), layout="constrained")
    ax = fig.add_subplot()
    generations = np.arange(1, len(curve.best) + 1)
    ax.plot(generations, curve.elites, label="the best quarter's mean")
    ax.plot(generations, curve.best, label="the best candidate")
    ax.axhline(pd_mean, color="0.4", linestyle="--", label="PD, eq (20), over the training seeds")
    ax.set(xlabel="generation", ylabel="J of eq (19), rad$^2$, mean over its wave seeds",
           title=title, ylim=(0.0, 2.0 * max(pd_mean, min(curve.elites))))
    ax.grid(alpha=0.3)
    ax.legend()
    return fig


def table(J: dict[str, np.ndarray], seeds: list[int]) -> list[str]:
    """A Markdown table: each policy's mean, spread and worst J on ``seeds``, and its share
    of the first's mean."""
    first = average(next(iter(J.values())))
    lines = [f"J of eq (19), rad^2, over wave seeds {seeds[0]}..{seeds[-1]} "
             f"({len(seeds)} seeds):", "", "| autopilot | mean | std | worst | vs first |",
             "|---|---|---|---|---|"]
    for name, values in J.items():
        lines.append(f"| {name} | {average(values):.2f} | {np.std(values):.2f} | "
                     f"{np.max(values):.2f} | {average(values) / first - 1:+.1%} |")
    return lines
