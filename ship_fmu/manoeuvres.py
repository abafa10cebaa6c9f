"""Standard manoeuvres (IMO MSC.137(76) definitions) on the in-process vessel.

The ship starts in steady straight running; a positive rudder turns it to port
(see ``thrusters``), so headings here go negative first.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .vessel import Vessel, VesselParameters

DT = 0.1


@dataclass(frozen=True)
class TurningCircle:
    advance: float               # m, along the approach course at 90 deg heading change
    transfer: float              # m, across the approach course at 90 deg
    tactical_diameter: float     # m, across the approach course at 180 deg
    steady_yaw_rate: float       # rad/s, signed
    steady_speed: float          # m/s, sqrt(u^2 + v^2) in the steady turn


@dataclass(frozen=True)
class ZigZagResult:
    first_overshoot: float       # rad
    second_overshoot: float      # rad


class ZigZagProgram:
    """Rudder program of a zig-zag test: reverse the rudder at +-psi_switch."""

    def __init__(self, delta: float = math.radians(20.0),
                 psi_switch: float = math.radians(20.0)):
        self.delta, self.psi_switch = delta, psi_switch
        self.command = delta          # first execute: positive rudder, turn to port
        self.reversals = 0

    def __call__(self, psi: float) -> float:
        """Rudder command for the current heading deviation psi."""
        if self.command > 0.0 and psi <= -self.psi_switch:
            self.command, self.reversals = -self.delta, self.reversals + 1
        elif self.command < 0.0 and psi >= self.psi_switch:
            self.command, self.reversals = self.delta, self.reversals + 1
        return self.command


def _crossing(track: list[tuple[float, float, float]], psi_target: float) -> tuple[float, float]:
    """(x, y) where |psi| first reaches psi_target, linearly interpolated."""
    for (x0, y0, p0), (x1, y1, p1) in zip(track, track[1:]):
        if abs(p1) >= psi_target > abs(p0):
            w = (psi_target - abs(p0)) / (abs(p1) - abs(p0))
            return x0 + w * (x1 - x0), y0 + w * (y1 - y0)
    raise ValueError(f"heading never changed by {math.degrees(psi_target):.0f} deg")


def turning_circle(delta: float = math.radians(35.0), t_end: float = 300.0,
                   params: VesselParameters = VesselParameters()) -> TurningCircle:
    """Turning circle from steady straight running along x with rudder delta."""
    vessel = Vessel(replace(params, x0=0.0, y0=0.0, psi0=0.0))
    track = [(vessel.x, vessel.y, vessel.psi)]
    for k in range(round(t_end / DT)):
        vessel.step(k * DT, DT, delta)
        track.append((vessel.x, vessel.y, vessel.psi))
    advance, transfer = _crossing(track, math.pi / 2)
    _, across_180 = _crossing(track, math.pi)
    return TurningCircle(advance=advance, transfer=abs(transfer),
                         tactical_diameter=abs(across_180),
                         steady_yaw_rate=vessel.r,
                         steady_speed=math.hypot(vessel.u, vessel.v))


def zigzag(delta: float = math.radians(20.0), psi_switch: float = math.radians(20.0),
           t_end: float = 300.0,
           params: VesselParameters = VesselParameters()) -> ZigZagResult:
    """First and second overshoot angles of a delta/psi_switch zig-zag test."""
    vessel = Vessel(replace(params, psi0=0.0))
    program = ZigZagProgram(delta, psi_switch)
    extremes = [0.0, 0.0]             # heading extremes after reversal 1 and 2
    for k in range(round(t_end / DT)):
        vessel.step(k * DT, DT, program(vessel.psi))
        if program.reversals in (1, 2):
            i = program.reversals - 1
            extremes[i] = max(extremes[i], abs(vessel.psi))
        elif program.reversals > 2:
            break
    if program.reversals < 3:
        raise ValueError("zig-zag did not complete three rudder reversals")
    return ZigZagResult(first_overshoot=extremes[0] - psi_switch,
                        second_overshoot=extremes[1] - psi_switch)
