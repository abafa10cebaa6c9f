"""Waypoint guidance as an FMI 2.0 co-simulation FMU (fmus/guidance.fmu), eq (18).

psi_d and wp_index are direct feedthrough from the position: evaluated when read,
with the leg switch committed at the end of each step.
"""
from autopilot_fmu.guidance import PAPER_ROUTE, R_ACCEPT, WaypointGuidance
from fmukit.slave import ModelSlave, Var


class GuidanceSlave(ModelSlave):
    model_name = "guidance"
    description = ("Waypoint guidance: desired course of the active leg (Tomera 2010, eq 18), "
                   "switching inside the circle of acceptance or once past the waypoint")
    variables = (
        Var.input("x", 0.0, "m", "ship north position"),
        Var.input("y", 0.0, "m", "ship east position"),
        Var.output("psi_d", "rad", "desired course, eq (18)",
                   depends=("x", "y", "waypoints", "R_accept"),
                   get=lambda s: s.model.psi_d(s.x, s.y)),
        Var.output("wp_index", description="index of the waypoint steered to; "
                   "the number of waypoints once past the last", kind=int,
                   depends=("x", "y", "waypoints", "R_accept"),
                   get=lambda s: s.model.wp_index(s.x, s.y)),
        Var.parameter("waypoints", PAPER_ROUTE,
                      description="route 'x0,y0;x1,y1;...' in m, north and east"),
        Var.parameter("R_accept", R_ACCEPT, "m", "radius of the circle of acceptance, "
                      "> 0", 0.0, 1e6),
    )

    def build_model(self) -> WaypointGuidance:
        return WaypointGuidance(self.waypoints, self.R_accept)

    def step_model(self, t: float, h: float) -> None:
        self.model.update(self.x, self.y)
