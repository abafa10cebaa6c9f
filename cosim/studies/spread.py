"""How many of a run's digits mean something? The run again with a last bit changed.

The sliding-mode loop chatters, and in waves every loop switches legs at an instant
that a tiny change can move by a step: a difference in the last bit of one number
grows into percent of J. A CPU or C library that rounds one operation differently
moves a run by as much. The ensemble here makes that size visible: the run itself,
and the same run with one parameter moved by k units in the last place (ulp),
k = +-1 ... +-ulps: the ship's initial surge speed u0 (a change that the run then
carries), and the direction the waves travel to psi_w (a change to the wave loads at
every step, as a C library's sin that rounds differently makes). The range of each figure of eq (19) over it is
the precision a published figure of that run has; a figure whose range rounds to one
printed value is exact at the printed digits.

Members run on the in-process backend (the same bits as through FMI, faster); a
component that cannot runs through FMI.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

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
    """The range of each figure of eq (19) over a perturbation ensemble."""

    runs: int
    ulps: int                       # each member moved one parameter by -ulps ... +ulps
    ranges: dict[str, tuple[float, float]]      # figure: (min, max)

    def wider_than(self, figure: str, digits: int = 2) -> bool:
        """Whether the range of ``figure`` shows at ``digits`` decimals."""
        low, high = self.ranges[figure]
        return f"{low:.{digits}f}" != f"{high:.{digits}f}"

    def describe(self, digits: int = 2) -> str:
        """'psi_E 467.07-486.88, J 592.29-619.61', or 'every figure as printed'."""
        wide = [f"{figure} {low:.{digits}f}-{high:.{digits}f}"
                for figure, (low, high) in self.ranges.items()
                if self.wider_than(figure, digits)]
        return ", ".join(wide) if wide else "every figure as printed"


def spread(system: SystemDescription, overrides: dict[str, dict[str, Any]] | None = None,
           ulps: int = 20, lam: float = LAMBDA, coupling: str = "gauss-seidel",
           stop_time: float | None = None,
           progress: Callable[[int, int], None] | None = None) -> Spread:
    """The run and 2 ulps runs for each of ``PERTURBED``, its value moved by -ulps ...
    +ulps; the range of eq (19) over them.

    ValueError if ulps < 1 or the system lacks a perturbed parameter; RuntimeError
    naming the member if a run fails.
    """
    if ulps < 1:
        raise ValueError(f"spread: ulps must be >= 1, got {ulps}")
    overrides = {c: dict(v) for c, v in (overrides or {}).items()}
    members = [(None, 0)] + [(p, k) for p in PERTURBED
                             for j in range(1, ulps + 1) for k in (-j, j)]
    master = Master(system, coupling=coupling, backend="inprocess", overrides=overrides)
    costs: list[Cost] = []
    try:
        for component, name in PERTURBED:
            instance = master.instances.get(component)
            if instance is None or name not in instance.variables:
                raise ValueError(f"spread: the system {system.name!r} has no "
                                 f"{component}.{name} to perturb")
        for i, (parameter, k) in enumerate(members):
            if parameter is not None:
                component, name = parameter
                value = nudged(float(nominal[component][name]), k)
                master.configure({**overrides, component: {**overrides.get(component, {}),
                                                           name: value}})
                master.reset()
            recording = master.run(stop_time)
            if recording.error:
                moved = f"{'.'.join(parameter)} moved by {k} ulp" if parameter else "nominal"
                raise RuntimeError(f"spread: the run ({moved}) failed: {recording.error}")
            if parameter is None:
                nominal = master.parameter_values
            costs.append(cost(recording, lam))
            if progress is not None:
                progress(i + 1, len(members))
    finally:
        master.free()
    ranges = {f: (min(getattr(c, f) for c in costs), max(getattr(c, f) for c in costs))
              for f in FIGURES}
    return Spread(len(costs), ulps, ranges)
