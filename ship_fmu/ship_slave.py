"""The vessel as an FMI 2.0 co-simulation FMU (fmus/ship.fmu); no direct feedthrough (the
rudder acts through the steering gear and the hull's inertia)."""
import math
from dataclasses import fields, replace

from fmukit.slave import ModelSlave, Var
from ship_fmu.vessel import N_PROPELLER, Vessel, VesselParameters

_P = VesselParameters()
N_MAX = 50.0                    # rev/s, the largest shaft speed (8.13 gives 0.3 m/s)
ANGLE_MAX = 1e6                 # rad, |psi0|, |psi_w|: past 1e307 sin(2 beta) is not finite
_SEA = ("Hs", "T0", "psi_w", "wave_seed", "wave_components", "psi0")


class ShipSlave(ModelSlave):
    model_name = "ship"
    description = ("CyberShip II (1:70 supply ship model), nonlinear 3-DOF manoeuvring model "
                   "with propellers, rudders, rate-limited steering gear and wave loads "
                   "(Tomera 2010, eqs 1-17)")
    variables = (
        Var.input("delta_c", 0.0, "rad", "commanded rudder angle, both rudders; "
                  "positive turns the ship to port"),
        Var.input("n1", N_PROPELLER, "rev/s", "main propeller 1 shaft speed", -N_MAX, N_MAX),
        Var.input("n2", N_PROPELLER, "rev/s", "main propeller 2 shaft speed", -N_MAX, N_MAX),
        Var.input("n3", 0.0, "rev/s", "bow thruster shaft speed", -N_MAX, N_MAX),
        Var.output("x", "m", "north position", depends=("x0",)),
        Var.output("y", "m", "east position", depends=("y0",)),
        Var.output("psi", "rad", "heading, continuous (not wrapped)", depends=("psi0",)),
        Var.output("u", "m/s", "surge velocity (through the water)", depends=("u0",)),
        Var.output("v", "m/s", "sway velocity (through the water)", depends=("v0",)),
        Var.output("r", "rad/s", "yaw rate", depends=("r0",)),
        Var.output("delta", "rad", "actual rudder angle (steering gear output)"),
        Var.output("X_w", "N", "wave surge force, eq (14)", depends=_SEA),
        Var.output("Y_w", "N", "wave sway force, eq (15)", depends=_SEA),
        Var.output("N_w", "N.m", "wave yaw moment, eq (16)", depends=_SEA),
        Var.parameter("x0", _P.x0, "m", "initial north position"),
        Var.parameter("y0", _P.y0, "m", "initial east position"),
        Var.parameter("psi0", _P.psi0, "rad", "initial heading", -ANGLE_MAX, ANGLE_MAX),
        Var.parameter("u0", _P.u0, "m/s", "initial surge velocity", -5.0, 5.0),
        Var.parameter("v0", _P.v0, "m/s", "initial sway velocity", -5.0, 5.0),
        Var.parameter("r0", _P.r0, "rad/s", "initial yaw rate", -5.0, 5.0),
        Var.parameter("delta_max", _P.delta_max, "rad", "rudder stops, > 0", 0.0, math.pi / 2),
        Var.parameter("delta_rate_max", _P.delta_rate_max, "rad/s", "steering gear rate "
                      "limit; tunable: 0 from a time on is a failed gear", 0.0, 10.0,
                      tunable=True),
        Var.parameter("Hs", _P.Hs, "m", "significant wave height; 0 = calm water (0.1 m is "
                      "7 m at full scale)", 0.0, 0.1),
        Var.parameter("T0", _P.T0, "s", "modal period of the wave spectrum", 0.1, 10.0),
        Var.parameter("psi_w", _P.psi_w, "rad", "wave direction", -ANGLE_MAX, ANGLE_MAX),
        Var.parameter("wave_seed", _P.wave_seed, description="seed of the wave realisation",
                      min=0, max=2**31 - 1),
        Var.parameter("wave_components", _P.wave_components,
                      description="number of regular wave components", min=1, max=5000),
        Var.parameter("h_max", _P.h_max, "s", "largest RK4 step; a communication step is "
                      "cut into equal sub-steps no longer than this (RK4 diverges in "
                      "the steepest valid seas beyond about 0.4 s)", 1e-4, 0.2),
        Var.input("V_c", 0.0, "m/s", "ocean current speed (an environment FMU's output); u "
                  "and v are then relative to the water", 0.0, 5.0),
        Var.input("beta_c", 0.0, "rad", "direction the current flows towards, from north",
                  -ANGLE_MAX, ANGLE_MAX),
        Var.input("V_w", 0.0, "m/s", "wind speed (an environment FMU's output; 10 m/s at "
                  "10 m above the water at full scale is 1.2 m/s at 1:70)", 0.0, 20.0),
        Var.input("beta_w", 0.0, "rad", "direction the wind blows towards, from north",
                  -ANGLE_MAX, ANGLE_MAX),
    )

    def build_model(self) -> Vessel:
        return Vessel(VesselParameters(**{f.name: getattr(self, f.name)
                                          for f in fields(VesselParameters)}))

    def tune_model(self, name: str) -> None:
        self.model.params = replace(self.model.params, **{name: getattr(self, name)})

    def step_model(self, t: float, h: float) -> None:
        self.model.step(t, h, self.delta_c, self.n1, self.n2, self.n3, self.V_c, self.beta_c,
                        self.V_w, self.beta_w)
