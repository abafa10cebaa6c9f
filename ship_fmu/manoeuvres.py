"""Standard manoeuvres (IMO MSC.137(76) definitions): the rudder program of a turning
circle or a zig-zag test, and the ship run alone under it (``trial``).

The ship starts in steady straight running; a positive rudder turns it to port
(see ``thrusters``), so headings here go negative first. The manoeuvre FMU
(``manoeuvre_slave``) runs the program; the figures of a run, recorded or from
``trial``, are post-processing: ``cosim.analysis.manoeuvres``.
"""
from __future__ import annotations

import math
from dataclasses import replace

from fmukit.timebase import step_count

from .vessel import Vessel, VesselParameters

DT = 0.1


class RudderProgram:
    """Rudder command of a turning circle or a zig-zag test.

    Executes ``delta`` at t = 0. With psi_switch > 0 the rudder is reversed each time
    the heading deviation passes -+psi_switch (a delta/psi_switch zig-zag); with
    psi_switch = 0 it is held (a turning circle). ``command`` evaluates the rule at
    a heading without committing it; ``update`` commits it.
    """

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


def trial(program: RudderProgram, t_end: float, params: VesselParameters) -> dict[str, list]:
    """The ship alone under ``program`` for ``t_end`` s in steps of ``DT``, from steady
    straight running at the origin along x: its x, y, psi, u, v and r at the start of
    each step, and the program's reversals so far."""
    vessel = Vessel(replace(params, x0=0.0, y0=0.0, psi0=0.0))
    track = {name: [] for name in ("x", "y", "psi", "u", "v", "r", "reversals")}
    for k in range(step_count(0.0, t_end, DT)):
        delta_c = program.command(vessel.psi)
        program.update(vessel.psi)
        for name in track:
            source = program if name == "reversals" else vessel
            track[name].append(getattr(source, name))
        vessel.step(k * DT, DT, delta_c)
    return track
