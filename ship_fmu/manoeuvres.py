"""The rudder program of a turning circle or a zig-zag test (IMO MSC.137(76)).

A positive rudder turns the ship to port, so headings go negative first. The figures of a
run are post-processing (``cosim.analysis.manoeuvres``)."""
from __future__ import annotations

import math


class RudderProgram:
    """Executes ``delta`` at t = 0; with psi_switch > 0 reverses it each time the heading
    deviation passes -+psi_switch (a zig-zag), with psi_switch = 0 holds it (a turning
    circle). ``command`` evaluates the rule at a heading, ``update`` commits it."""

    def __init__(self, delta: float = math.radians(20.0),
                 psi_switch: float = math.radians(20.0)):
        for name, value in (("delta", delta), ("psi_switch", psi_switch)):
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"parameter {name} must be finite and >= 0, got {value}")
        self.delta, self.psi_switch = delta, psi_switch
        self.sign, self.reversals = 1, 0

    def _next(self, psi: float) -> tuple[int, int]:
        """(sign, reversals) after the rule is applied at heading deviation psi."""
        if self.psi_switch > 0.0 and self.sign * psi <= -self.psi_switch:
            return -self.sign, self.reversals + 1
        return self.sign, self.reversals

    def command(self, psi: float) -> float:
        """Rudder command at heading deviation psi, rad."""
        return self._next(psi)[0] * self.delta

    def reversals_at(self, psi: float) -> int:
        """Rudder reversals so far, counting one due at heading deviation psi."""
        return self._next(psi)[1]

    def update(self, psi: float) -> None:
        self.sign, self.reversals = self._next(psi)

    def snapshot(self) -> dict[str, int]:
        return {"sign": self.sign, "reversals": self.reversals}

    def restore(self, snapshot: dict[str, int]) -> None:
        self.sign, self.reversals = int(snapshot["sign"]), int(snapshot["reversals"])
