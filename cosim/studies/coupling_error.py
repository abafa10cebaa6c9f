"""The accuracy study's parts 2 and 3, the coupling error closed loop: each of the paper's runs
through our master at the 0.1 s communication step, Gauss-Seidel and Jacobi, against the
monolithic reference (``monolithic``) by the figures of eq (19) and the largest heading
difference; then J's distance from it over communication steps of 0.4 s to 0.0125 s."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from .. import scenarios
from ..analysis.cost import LAMBDA
from ..analysis.metrics import cost_terms
from ..core.master import Master
from .integration_error import H
from .monolithic import monolithic

PAPER_RUNS = ("calm_pd", "calm_smc", "waves_pd", "waves_smc")
COUPLINGS = ("gauss-seidel", "jacobi")
STEPS = (0.4, 0.2, 0.1, 0.05, 0.025, 0.0125)   # s, communication steps of part 3


def cosimulation(name: str, step: float, coupling: str,
                 stop_time: float | None = None) -> dict[str, np.ndarray]:
    """Our master in-process at communication step ``step``, sampled on the 0.1 s grid (a
    coarser step at its own points, each standing for step / 0.1 samples: ``weight``)."""
    system = dataclasses.replace(scenarios.load(name), step_size=step)
    with Master(system, coupling=coupling, backend="inprocess") as master:
        recording = master.run(stop_time)
    every = max(1, round(H / step))
    return {"psi_d": recording["guidance.psi_d"][::every], "psi": recording["ship.psi"][::every],
            "delta": recording["ship.delta"][::every], "weight": max(1.0, step / H)}


def figures(run: dict[str, np.ndarray]) -> dict[str, float]:
    """psi_E, sum delta^2 and J of eq (19) on the 0.1 s grid."""
    weight = run.get("weight", 1.0)
    psi_E, sum_delta2 = (weight * f for f in cost_terms(run["psi_d"], run["psi"], run["delta"]))
    return {"psi_E": psi_E, "sum_delta2": sum_delta2, "J": psi_E + LAMBDA * sum_delta2}


def closed_loop(name: str, stop_time: float | None = None) -> dict[str, dict]:
    """Part 2 for one run: the figures of the reference and of both couplings at 0.1 s."""
    reference_run = monolithic(scenarios.load(name), stop_time)
    out = {"monolithic": {**figures(reference_run), "max_dpsi": 0.0}}
    for coupling in COUPLINGS:
        run = cosimulation(name, H, coupling, stop_time)
        out[coupling] = {**figures(run),
                         "max_dpsi": float(np.abs(run["psi"] - reference_run["psi"]).max())}
    return out


def closed_loop_table(results: dict[str, dict]) -> str:
    lines = ["| run | model | psi_E (rad^2) | sum delta^2 (rad^2) | J "
             "| max abs(psi - psi_ref) (deg) |", "|---|---|---:|---:|---:|---:|"]
    for name, result in results.items():
        for model in ("monolithic", *COUPLINGS):
            f = result[model]
            lines.append(f"| {name} | {model} | {f['psi_E']:.2f} | {f['sum_delta2']:.3f} | "
                         f"{f['J']:.2f} | {math.degrees(f['max_dpsi']):.3f} |")
    return "\n".join(lines)


def convergence(name: str, reference_figures: dict[str, float], steps=STEPS,
                stop_time: float | None = None) -> dict[str, list[dict]]:
    """Part 3 for one run: the figures at each step and coupling, and J's relative distance
    from the monolithic value."""
    J = reference_figures["J"]
    out: dict[str, list[dict]] = {coupling: [] for coupling in COUPLINGS}
    for coupling in COUPLINGS:
        for step in steps:
            f = figures(cosimulation(name, step, coupling, stop_time))
            out[coupling].append({"step": step, **f, "J_error": abs(f["J"] - J) / J})
    return out


def convergence_table(results: dict[str, dict], references: dict[str, dict]) -> str:
    steps = [r["step"] for r in next(iter(next(iter(results.values())).values()))]
    lines = ["| run | coupling | " + " | ".join(f"J at {s:g} s" for s in steps)
             + " | order | J monolithic |", "|---|---|" + "---:|" * (len(steps) + 2)]
    for name, by_coupling in results.items():
        for coupling, rows in by_coupling.items():
            errors = [r["J_error"] for r in rows]
            order = [math.log2(a / b) for a, b in zip(errors, errors[1:]) if a > 0 and b > 0]
            lines.append(f"| {name} | {coupling} | " + " | ".join(f"{r['J']:.2f}" for r in rows)
                         + f" | {np.median(order) if order else math.nan:.2f} | "
                           f"{references[name]['J']:.2f} |")
    return "\n".join(lines)


def convergence_figure(results: dict[str, dict], path: Path) -> Path:
    """|J - J_monolithic| / J_monolithic against the communication step, log-log."""
    import matplotlib.ticker
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 4.5))
    ax = fig.subplots()
    for name, by_coupling in results.items():
        for coupling, rows in by_coupling.items():
            ax.loglog([r["step"] for r in rows], [max(r["J_error"], 1e-12) for r in rows],
                      "o-" if coupling == "gauss-seidel" else "s--",
                      label=f"{name}, {coupling}")
    steps = [r["step"] for r in next(iter(next(iter(results.values())).values()))]
    ax.set_xticks(steps, [f"{step:g}" for step in steps])
    ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    ax.set(xlabel="communication step (s)", ylabel="|J - J monolithic| / J monolithic",
           title="Co-simulation converges to the monolithic model")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path
