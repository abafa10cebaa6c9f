"""Standard manoeuvres (IMO MSC.137(76) definitions): rudder program and figures.

The ship starts in steady straight running; a positive rudder turns it to port
(see ``thrusters``), so headings here go negative first. The figures are computed
from recorded trajectories, so the in-process runs below and the co-simulated
scenarios (``cosim/scenarios/turning_circle.ssd``, ``zigzag_20_20.ssd``) share them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fmukit.timebase import step_count

from .vessel import Vessel, VesselParameters

DT = 0.1


@dataclass(frozen=True)
class TurningCircle:
    advance: float               # m, along the approach course at 90 deg heading change
    transfer: float              # m, across the approach course at 90 deg
    tactical_diameter: float     # m, across the approach course at 180 deg
    steady_yaw_rate: float       # rad/s, signed, at the end of the run
    steady_speed: float          # m/s, sqrt(u^2 + v^2) at the end of the run


@dataclass(frozen=True)
class ZigZagResult:
    first_overshoot: float       # rad; NaN if the turn was never checked (no second reversal)
    second_overshoot: float      # rad; NaN if there was no third reversal
    reversals: int               # rudder reversals the test reached

    @property
    def checked(self) -> bool:
        """Whether the ship checked its turns: three reversals, both overshoots defined."""
        return self.reversals >= 3


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


def crossing(x: np.ndarray, y: np.ndarray, psi: np.ndarray,
              target: float) -> tuple[float, float]:
    """(x, y) where |psi| first reaches target, linearly interpolated."""
    heading = np.abs(psi)
    i = int(np.argmax(heading >= target))
    if heading[i] < target or i == 0:
        raise ValueError(f"heading never changed by {math.degrees(target):.0f} deg")
    w = (target - heading[i - 1]) / (heading[i] - heading[i - 1])
    return x[i - 1] + w * (x[i] - x[i - 1]), y[i - 1] + w * (y[i] - y[i - 1])


def turning_circle_figures(x, y, psi, u, v, r) -> TurningCircle:
    """Turning-circle figures of a run that starts along x at psi = 0."""
    x, y, psi = map(np.asarray, (x, y, psi))
    advance, transfer = crossing(x, y, psi, math.pi / 2)
    _, across = crossing(x, y, psi, math.pi)
    return TurningCircle(advance=float(advance), transfer=float(abs(transfer)),
                         tactical_diameter=float(abs(across)),
                         steady_yaw_rate=float(r[-1]),
                         steady_speed=float(math.hypot(u[-1], v[-1])))


def zigzag_figures(psi, reversals, psi_switch: float) -> ZigZagResult:
    """Overshoot angles after the first and second rudder reversal.

    An overshoot is measured once the next reversal shows the turn was checked; a
    ship that never checks its turn (a straight-line unstable one, with too little
    rudder) leaves it NaN.
    """
    psi, reversals = np.abs(np.asarray(psi)), np.asarray(reversals)
    reached = int(reversals.max())

    def overshoot(n: int) -> float:
        return float(psi[reversals == n].max() - psi_switch) if reached > n else math.nan
    return ZigZagResult(overshoot(1), overshoot(2), reached)


def _run(program: RudderProgram, t_end: float, params: VesselParameters) -> dict[str, list]:
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


def turning_circle(delta: float = math.radians(35.0), t_end: float = 300.0,
                   params: VesselParameters = VesselParameters()) -> TurningCircle:
    """Turning circle from steady straight running with rudder delta."""
    track = _run(RudderProgram(delta, 0.0), t_end, params)
    return turning_circle_figures(*(track[n] for n in ("x", "y", "psi", "u", "v", "r")))


def zigzag(delta: float = math.radians(20.0), psi_switch: float = math.radians(20.0),
           t_end: float = 300.0,
           params: VesselParameters = VesselParameters()) -> ZigZagResult:
    """First and second overshoot angles of a delta/psi_switch zig-zag test."""
    track = _run(RudderProgram(delta, psi_switch), t_end, params)
    return zigzag_figures(track["psi"], track["reversals"], psi_switch)
