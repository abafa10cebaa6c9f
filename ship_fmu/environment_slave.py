"""The environment as a co-simulation FMU (fmus/environment.fmu): the ocean current
(ship_fmu.environment) as outputs that a scenario wires to the ship's V_c and beta_c inputs,
so that a user can put an environment of their own in its place. With its defaults the
current is nil and the ship runs as in still water."""
import math

from fmukit.slave import ModelSlave, Var
from ship_fmu.environment import Current

_C = Current()
_CURRENT = ("V_c_mean", "beta_c_mean")


class EnvironmentSlave(ModelSlave):
    model_name = "environment"
    description = ("Ocean current: speed and direction first-order Gauss-Markov processes "
                   "about their means (Fossen 2011, sec. 8.3)")
    variables = (
        Var.output("V_c", "m/s", "current speed", depends=_CURRENT,
                   get=lambda s: s.model.V),
        Var.output("beta_c", "rad", "direction the current flows towards, from north",
                   depends=_CURRENT, get=lambda s: s.model.beta),
        Var.parameter("V_c_mean", _C.V_mean, "m/s", "mean current speed (1 m/s at full "
                      "scale is 0.12 m/s at 1:70)", 0.0, 5.0),
        Var.parameter("beta_c_mean", _C.beta_mean, "rad", "mean direction, towards, from "
                      "north", -1e6, 1e6),
        Var.parameter("T_c", _C.T_c, "s", "correlation time of speed and direction, > 0",
                      0.0, 1e9),
        Var.parameter("sigma_V", _C.sigma_V, "m/s", "speed's standard deviation", 0.0, 5.0),
        Var.parameter("sigma_beta", _C.sigma_beta, "rad", "direction's standard deviation",
                      0.0, math.pi),
        Var.parameter("current_seed", _C.seed, description="seed of the current's "
                      "variations", min=0, max=2**31 - 1),
    )

    def build_model(self) -> Current:
        return Current(self.V_c_mean, self.beta_c_mean, self.T_c, self.sigma_V,
                       self.sigma_beta, self.current_seed)

    def step_model(self, t: float, h: float) -> None:
        self.model.step(h)
