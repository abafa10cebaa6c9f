"""PD autopilot, eq (20): delta_c = K_P (psi - psi_d) + K_D r, stabilising as printed (a
positive rudder turns this ship to port); the error wrapped to (-pi, pi]: the short way."""
from dataclasses import dataclass

from fmukit.numerics import wrap


@dataclass(frozen=True)
class PDAutopilot:
    Kp: float = 2.0       # rad of rudder per rad of heading error
    Kd: float = 50.0      # rad of rudder per rad/s of yaw rate (s); the FMU checks both finite

    def command(self, psi: float, r: float, psi_d: float) -> float:
        return self.Kp * wrap(psi - psi_d) + self.Kd * r

    def snapshot(self) -> dict:
        return {}                          # memoryless

    def restore(self, snapshot: dict) -> None:
        pass
