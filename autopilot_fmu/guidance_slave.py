"""Waypoint guidance as an FMI 2.0 co-simulation FMU (fmus/guidance.fmu), eq (18): psi_d and
wp_index direct feedthrough from the position, the leg switch committed at each step's end."""
from autopilot_fmu.guidance import (COORDINATES, MAX_WAYPOINTS, PAPER_ROUTE, R_ACCEPT,
                                    ROUTE_PARAMETERS, WaypointGuidance, route)
from fmukit.slave import ModelSlave, Var

_ROUTE = ROUTE_PARAMETERS + ("R_accept",)


class GuidanceSlave(ModelSlave):
    model_name = "guidance"
    description = ("Waypoint guidance: desired course of the active leg (Tomera 2010, eq 18), "
                   "switching inside the circle of acceptance or once past the waypoint")
    variables = (
        Var.input("x", 0.0, "m", "ship north position"),
        Var.input("y", 0.0, "m", "ship east position"),
        Var.output("psi_d", "rad", "desired course, eq (18)", depends=("x", "y") + _ROUTE,
                   get=lambda s: s.model.psi_d(s.x, s.y)),
        Var.output("wp_index", description="index of the waypoint steered to; "
                   "the number of waypoints once past the last", kind=int,
                   depends=("x", "y") + _ROUTE,
                   get=lambda s: s.model.wp_index(s.x, s.y)),
        Var.parameter("waypoints", PAPER_ROUTE,
                      description="route 'x0,y0;x1,y1;...' in m, north and east; used "
                                  "while n_waypoints = 0"),
        Var.parameter("R_accept", R_ACCEPT, "m", "radius of the circle of acceptance, "
                      "> 0", 0.0, 1e6),
        Var.parameter("n_waypoints", 0, description=(
            "points of the numeric route wp0 .. wp<n-1>, 2 or more; 0: the route is the "
            "String waypoints (for hosts without String parameters)"), min=0,
            max=MAX_WAYPOINTS),
        *(Var.parameter(name, 0.0, "m", f"waypoint {k // 2} of the numeric route, "
                        f"{('north', 'east')[k % 2]}; 0 where unused")
          for k, name in enumerate(COORDINATES)),
    )

    def build_model(self) -> WaypointGuidance:
        return WaypointGuidance(route({name: getattr(self, name) for name in ROUTE_PARAMETERS}),
                                self.R_accept)

    def step_model(self, t: float, h: float) -> None:
        self.model.update(self.x, self.y)
