"""PD autopilot, eq (20): delta_c = K_P (psi - psi_d) + K_D r.

A positive rudder turns this ship to port (r < 0), so eq (20) as printed is a stabilising
feedback. The heading error is wrapped to (-pi, pi]: the ship turns the short way.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from fmukit.numerics import wrap


@dataclass(frozen=True)
class PDAutopilot:
    Kp: float = 2.0       # rad of rudder per rad of heading error
    Kd: float = 50.0      # rad of rudder per rad/s of yaw rate (s)

    def __post_init__(self) -> None:
        for name in ("Kp", "Kd"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"parameter {name} = {getattr(self, name)} is not finite")

    def command(self, psi: float, r: float, psi_d: float) -> float:
        """Commanded rudder angle delta_c, rad."""
        return self.Kp * wrap(psi - psi_d) + self.Kd * r

    def snapshot(self) -> dict:
        return {}                          # memoryless

    def restore(self, snapshot: dict) -> None:
        pass
