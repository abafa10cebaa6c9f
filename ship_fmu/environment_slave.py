"""The environment as a co-simulation FMU (fmus/environment.fmu): the ocean current and the
wind (ship_fmu.environment) as outputs that a scenario wires to the ship's V_c, beta_c, V_w
and beta_w inputs, so that a user can put an environment of their own in its place. With its
defaults both are nil and the ship runs as in still water and still air."""
import math

from fmukit.slave import ModelSlave, Var
from ship_fmu.environment import Current, Environment, Wind

_C = Current()
_CURRENT = ("V_c_mean", "beta_c_mean")
_WIND = ("V_w_mean", "beta_w_mean", "gust_components", "wind_seed")


class EnvironmentSlave(ModelSlave):
    model_name = "environment"
    description = ("Ocean current: speed and direction first-order Gauss-Markov processes "
                   "about their means (Fossen 2011, sec. 8.3); wind: a mean with gusts from "
                   "the NORSOK N-003 spectrum, Froude-scaled to 1:70")
    variables = (
        Var.output("V_c", "m/s", "current speed", depends=_CURRENT,
                   get=lambda s: s.model.current.V),
        Var.output("beta_c", "rad", "direction the current flows towards, from north",
                   depends=_CURRENT, get=lambda s: s.model.current.beta),
        Var.output("V_w", "m/s", "wind speed", depends=_WIND,
                   get=lambda s: s.model.wind.speed(s.model.t)),
        Var.output("beta_w", "rad", "direction the wind blows towards, from north",
                   depends=_WIND, get=lambda s: s.model.wind.beta),
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
        Var.parameter("V_w_mean", 0.0, "m/s", "mean wind speed at 10 m (10 m/s at full scale "
                      "is 1.2 m/s at 1:70)", 0.0, 10.0),
        Var.parameter("beta_w_mean", 0.0, "rad", "direction the wind blows towards, from "
                      "north", -1e6, 1e6),
        Var.parameter("gust_components", 0, description="harmonics of the gusts (NORSOK "
                      "spectrum); 0: a steady wind", min=0, max=1000),
        Var.parameter("wind_seed", 0, description="seed of the gusts", min=0, max=2**31 - 1),
    )

    def build_model(self) -> Environment:
        return Environment(Current(self.V_c_mean, self.beta_c_mean, self.T_c, self.sigma_V,
                                   self.sigma_beta, self.current_seed),
                           Wind(self.V_w_mean, self.beta_w_mean, self.gust_components,
                                self.wind_seed), self.start_time or 0.0)

    def step_model(self, t: float, h: float) -> None:
        self.model.step(t, h)
