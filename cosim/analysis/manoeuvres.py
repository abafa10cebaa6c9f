"""The figures of a standard manoeuvre (IMO MSC.137(76)), from its recorded trajectory:
a turning circle's advance, transfer and tactical diameter, a zig-zag's overshoots.

A positive rudder turns the ship to port, so headings go negative first. The
co-simulated scenarios (``cosim/scenarios/turning_circle.ssd``, ``zigzag_20_20.ssd``:
``reports``, ``figures``) and the ship run alone in-process (``turning_circle``,
``zigzag``, by ``ship_fmu.trial``) share these figures.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ship_fmu.manoeuvres import RudderProgram
from ship_fmu.trial import trial
from ship_fmu.vessel import VesselParameters


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



def turning_circle(delta: float = math.radians(35.0), t_end: float = 300.0,
                   params: VesselParameters = VesselParameters()) -> TurningCircle:
    """Turning circle from steady straight running with rudder delta."""
    track = trial(RudderProgram(delta, 0.0), t_end, params)
    return turning_circle_figures(*(track[n] for n in ("x", "y", "psi", "u", "v", "r")))


def zigzag(delta: float = math.radians(20.0), psi_switch: float = math.radians(20.0),
           t_end: float = 300.0,
           params: VesselParameters = VesselParameters()) -> ZigZagResult:
    """First and second overshoot angles of a delta/psi_switch zig-zag test."""
    track = trial(RudderProgram(delta, psi_switch), t_end, params)
    return zigzag_figures(track["psi"], track["reversals"], psi_switch)
