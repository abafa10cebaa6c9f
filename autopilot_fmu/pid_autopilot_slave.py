"""PID heading autopilot with anti-windup, as an FMI 2.0 co-simulation FMU (fmus/pid_autopilot.fmu).

    delta_c = Kp e + Ki z + Kd r,   e = psi - psi_d wrapped to (-pi, pi],   dz/dt = e

z advances with the error at each step's start, only while |e| < e_int and the command is
inside the stops or the error winds it back: it never winds up. One file importing nothing
but fmukit, as your own autopilot would be (docs/own_autopilot.md walks through it).
"""
import math
from dataclasses import dataclass

from fmukit.autopilot import INPUTS, rudder_command
from fmukit.numerics import wrap
from fmukit.slave import ModelSlave, Var


@dataclass
class PIDAutopilot:
    Kp: float = 2.0                       # rad of rudder per rad of heading error
    Ki: float = 0.04                      # per rad s of integrated error (1/s)
    Kd: float = 50.0                      # per rad/s of yaw rate (s)
    delta_max: float = math.radians(35)   # rudder stops, rad
    e_int: float = math.radians(5)        # integrate only errors smaller than this, rad
    z: float = 0.0                        # integrated heading error, rad s

    def command(self, psi: float, r: float, psi_d: float) -> float:
        """Commanded rudder angle delta_c, rad."""
        return self.Kp * wrap(psi - psi_d) + self.Ki * self.z + self.Kd * r

    def step(self, h: float, psi: float, r: float, psi_d: float) -> None:
        """Integrate the heading error over a step of h s, unless that winds up."""
        e, u = wrap(psi - psi_d), self.command(psi, r, psi_d)
        if abs(e) < self.e_int and (abs(u) < self.delta_max or u * e < 0.0):
            self.z += e * h

    def snapshot(self) -> dict:
        return {"z": self.z}

    def restore(self, snapshot: dict) -> None:
        self.z = float(snapshot["z"])


_P = PIDAutopilot()


class PIDAutopilotSlave(ModelSlave):
    model_name = "pid_autopilot"
    description = "PID heading autopilot with anti-windup: eq (20) with integral action"
    variables = (
        *INPUTS,
        rudder_command(depends=("psi", "r", "psi_d", "Kp", "Ki", "Kd"),
                       get=lambda s: s.model.command(s.psi, s.r, s.psi_d)),
        Var.output("z", "rad.s", "integrated heading error"),
        Var.parameter("Kp", _P.Kp, "1", "heading error gain", -1e4, 1e4),
        Var.parameter("Ki", _P.Ki, "1/s", "integral gain", -1e4, 1e4),
        Var.parameter("Kd", _P.Kd, "s", "yaw rate gain", -1e4, 1e4),
        Var.parameter("delta_max", _P.delta_max, "rad", "rudder stops, for anti-windup",
                      0.0, math.pi / 2),
        Var.parameter("e_int", _P.e_int, "rad", "integrate only heading errors below this",
                      0.0, math.pi),
    )

    def build_model(self) -> PIDAutopilot:
        return PIDAutopilot(self.Kp, self.Ki, self.Kd, self.delta_max, self.e_int)

    def step_model(self, t: float, h: float) -> None:
        self.model.step(h, self.psi, self.r, self.psi_d)
