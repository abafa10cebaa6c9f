"""How many of a run's digits mean something? The run again with the initial surge speed u0
and the wave direction psi_w each moved by a few ulps: the largest change of each figure of
eq (19) is its precision, as a CPU that rounds otherwise could move it."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..analysis.metrics import LAMBDA, Cost, cost
from ..core.master import Master
from ..core.ssd import SystemDescription

FIGURES = ("psi_E", "delta_E", "J")
PERTURBED = (("ship", "u0"), ("ship", "psi_w"))     # moved by a few ulps, one at a time


def nudged(value: float, ulps: int) -> float:
    """``value`` moved by ``ulps`` units in the last place (toward -inf for ulps < 0)."""
    direction = math.copysign(math.inf, ulps)
    for _ in range(abs(ulps)):
        value = math.nextafter(value, direction)
    return value


@dataclass(frozen=True)
class Spread:
    """How far one last bit moves each figure of eq (19): the run's value and the largest
    change from it (not the range: another CPU's run may diverge either way)."""

    runs: int
    nominal: dict[str, float]       # figure: the unperturbed run's value
    deviation: dict[str, float]     # figure: the largest |member - nominal|

    def describe(self) -> str:
        """'psi_E 472.76 +- 18.67, J 612.45 +- 20.18': the figures whose value +- deviation
        shows at 2 decimals; or 'every figure as printed'."""
        value, change = self.nominal, self.deviation
        wide = [f"{f} {value[f]:.2f} +- {change[f]:.2f}" for f in FIGURES
                if f"{value[f] - change[f]:.2f}" != f"{value[f] + change[f]:.2f}"]
        return ", ".join(wide) or "every figure as printed"


def spread(system: SystemDescription, overrides: dict[str, dict[str, Any]] | None = None,
           ulps: int = 20, lam: float = LAMBDA, coupling: str = "gauss-seidel",
           stop_time: float | None = None) -> Spread:
    """The run and those with each of ``PERTURBED`` moved by -ulps ... +ulps, in-process;
    ValueError if the system lacks one; RuntimeError naming a failed run."""
    overrides = overrides or {}
    members = [(None, 0), *((p, k) for p in PERTURBED for j in range(1, ulps + 1) for k in (-j, j))]
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
    return Spread(len(costs), nominal, deviation)
