"""A rudder program as an FMI 2.0 co-simulation FMU (fmus/manoeuvre.fmu): delta_c is direct
feedthrough from the heading, a rudder reversal committed at the end of each step."""
import math

from fmukit.slave import DefaultExperiment, ModelSlave, Var
from ship_fmu.manoeuvres import RudderProgram


class ManoeuvreSlave(ModelSlave):
    model_name = "manoeuvre"
    description = ("Rudder program of a turning circle or a zig-zag test (IMO MSC.137(76)); "
                   "positive rudder turns CyberShip II to port")
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=300.0, step_size=0.1)
    variables = (
        Var.input("psi", 0.0, "rad", "heading deviation from the approach course"),
        Var.output("delta_c", "rad", "commanded rudder angle",
                   depends=("psi", "delta", "psi_switch"),
                   get=lambda s: s.model.command(s.psi)),
        Var.output("reversals", description="rudder reversals so far", kind=int,
                   depends=("psi", "psi_switch"),
                   get=lambda s: s.model.reversals_at(s.psi)),
        Var.parameter("delta", math.radians(20.0), "rad", "rudder angle executed at t = 0",
                      0.0, math.pi / 2),
        Var.parameter("psi_switch", math.radians(20.0), "rad",
                      "heading deviation that reverses the rudder; 0 holds it (turning circle)",
                      0.0, math.pi),
    )

    def build_model(self) -> RudderProgram:
        return RudderProgram(self.delta, self.psi_switch)

    def step_model(self, t: float, h: float) -> None:
        self.model.update(self.psi)
