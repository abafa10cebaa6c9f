"""How many of a run's digits mean something? The run again with a last bit changed.

The sliding-mode loop chatters, and in waves a leg switch can move by a step: a last-bit
difference grows into percent of J, as a CPU or C library that rounds otherwise would make.
The ensemble: the run, and the run with one parameter moved by k ulps, k = +-1 ... +-ulps:
the initial surge speed u0 (a change the run carries) and the wave direction psi_w (a change
to the wave loads at every step). The largest change of each figure of eq (19) over it is
the precision a published figure of that run has.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..analysis.cost import LAMBDA, Cost, cost
from ..core.master import Master
from ..core.ssd import SystemDescription

FIGURES = ("psi_E", "delta_E", "J")
PERTURBED = (("ship", "u0"), ("ship", "psi_w"))
"""The parameters moved by a few ulps, one at a time."""


def nudged(value: float, ulps: int) -> float:
    """``value`` moved by ``ulps`` units in the last place (toward -inf for ulps < 0)."""
    direction = math.copysign(math.inf, ulps)
    for _ in range(abs(ulps)):
        value = math.nextafter(value, direction)
    return value


@dataclass(frozen=True)
class Spread:
    """How far one last bit moves each figure of eq (19): the run's value and the largest
    change from it over the ensemble (not its range: the run itself may lie at either end,
    and another CPU's run may diverge either way)."""

    runs: int
    ulps: int                       # each member moved one parameter by -ulps ... +ulps
    nominal: dict[str, float]       # figure: the unperturbed run's value
    deviation: dict[str, float]     # figure: the largest |member - nominal|

    def wider_than(self, figure: str, digits: int = 2) -> bool:
        """Whether value +- deviation shows at ``digits`` decimals."""
        value, change = self.nominal[figure], self.deviation[figure]
        return f"{value - change:.{digits}f}" != f"{value + change:.{digits}f}"

    def describe(self, digits: int = 2) -> str:
        """'psi_E 472.76 +- 18.67, J 612.45 +- 20.18', or 'every figure as printed'."""
        wide = [f"{f} {self.nominal[f]:.{digits}f} +- {self.deviation[f]:.{digits}f}"
                for f in FIGURES if self.wider_than(f, digits)]
        return ", ".join(wide) if wide else "every figure as printed"


def spread(system: SystemDescription, overrides: dict[str, dict[str, Any]] | None = None,
           ulps: int = 20, lam: float = LAMBDA, coupling: str = "gauss-seidel",
           stop_time: float | None = None) -> Spread:
    """The run and 2 ulps runs for each of ``PERTURBED`` (in-process), moved by -ulps ...
    +ulps; ValueError if ulps < 1 or the system lacks a perturbed parameter; RuntimeError
    naming the member if a run fails."""
    if ulps < 1:
        raise ValueError(f"spread: ulps must be >= 1, got {ulps}")
    overrides = {c: dict(v) for c, v in (overrides or {}).items()}
    members = [(None, 0)] + [(p, k) for p in PERTURBED
                             for j in range(1, ulps + 1) for k in (-j, j)]
    costs: list[Cost] = []
    with Master(system, coupling=coupling, backend="inprocess", overrides=overrides) as master:
        for component, name in PERTURBED:
            instance = master.instances.get(component)
            if instance is None or name not in instance.variables:
                raise ValueError(f"spread: the system {system.name!r} has no "
                                 f"{component}.{name} to perturb")
        held: dict[str, dict[str, Any]] = {}     # the values the unperturbed run used
        for parameter, k in members:
            if parameter is not None:
                component, name = parameter
                value = nudged(float(held[component][name]), k)
                master.configure({**overrides, component: {**overrides.get(component, {}),
                                                           name: value}})
                master.reset()
            recording = master.run(stop_time)
            if recording.error:
                moved = f"{'.'.join(parameter)} moved by {k} ulp" if parameter else "nominal"
                raise RuntimeError(f"spread: the run ({moved}) failed: {recording.error}")
            if parameter is None:
                held = master.parameter_values
            costs.append(cost(recording, lam))
    nominal = {f: getattr(costs[0], f) for f in FIGURES}
    deviation = {f: max(abs(getattr(c, f) - nominal[f]) for c in costs) for f in FIGURES}
    return Spread(len(costs), ulps, nominal, deviation)
