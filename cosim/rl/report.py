"""What ``cosim.train`` shows: the learning curve, and the policy's J beside the PD's on
seeds training never saw."""
from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from autopilot_fmu.policy import Policy

from ..analysis.figures import new_figure
from ..core.recording import Recording
from ..ensemble.exact import tanh, wrap
from .cem import Curve, average


def learning_figure(curve: Curve, pd_mean: float, title: str) -> Figure:
    fig = new_figure(figsize=(7, 4), layout="constrained")
    ax = fig.add_subplot()
    generations = np.arange(1, len(curve.best) + 1)
    top = 2.0 * max(pd_mean, min(curve.elites))
    above = int(np.sum(np.array(curve.elites) > top))
    ax.plot(generations, curve.elites, label="mean J of the best quarter of the candidates"
            + (f" ({above} generation{'s' * (above > 1)} above the chart)" if above else ""))
    ax.plot(generations, curve.best, label="J of the best candidate")
    ax.axhline(pd_mean, color="0.4", linestyle="--", label="PD, eq (20), over the training seeds")
    ax.set(xlabel="generation", ylabel="J of eq (19), rad$^2$, mean over its wave seeds",
           title=title, ylim=(0.0, top))
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.grid(alpha=0.3)
    ax.legend()
    return fig


def policy_figure(policies: dict[str, Policy], run: Recording, title: str) -> Figure:
    """Each policy's delta_c against e (r = 0) and against r (e = 0), held at the stops as the
    gear holds it, over the range ``run`` went through, 90 % of its time shaded."""
    fig = new_figure(figsize=(10, 4), layout="constrained")
    stops = math.degrees(float(np.max(np.abs(run["ship.delta"])))) or 1.0
    e, r = wrap(run["ship.psi"] - run["guidance.psi_d"]), run["ship.r"]
    for column, (ax, label, values) in enumerate(zip(fig.subplots(1, 2), (
            "e = psi - psi_d (deg), r = 0", "r (deg/s), e = 0"), (e, r))):
        x = np.linspace(-np.max(np.abs(values)), np.max(np.abs(values)), 201)
        ax.axvspan(*np.degrees(np.quantile(values, [0.05, 0.95])), color="0.9",
                   label="90 % of the run's time")
        for name, policy in policies.items():
            inputs = (x, 0.0 * x) if column == 0 else (0.0 * x, x)
            ax.plot(np.degrees(x), np.clip(np.degrees(policy.act(*inputs, tanh=tanh)),
                                           -stops, stops), label=name)
        ax.set(xlabel=label, ylabel="delta_c (deg), within the run's largest rudder",
               ylim=(-1.1 * stops, 1.1 * stops))
        ax.grid(alpha=0.3)
    fig.axes[0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    return fig


def table(J: dict[str, np.ndarray], seeds: list[int]) -> list[str]:
    """A Markdown table: each policy's mean, spread and worst J on ``seeds``, and its mean
    against the first's."""
    name, values = next(iter(J.items()))
    first = average(values)
    lines = [f"J of eq (19), rad^2, over wave seeds {seeds[0]}..{seeds[-1]} "
             f"({len(seeds)} seeds):", "", f"| autopilot | mean | std | worst | vs {name} |",
             "|---|---|---|---|---|"]
    for name, values in J.items():
        lines.append(f"| {name} | {average(values):.2f} | {np.std(values):.2f} | "
                     f"{np.max(values):.2f} | {average(values) / first - 1:+.1%} |")
    return lines
