"""Line-of-sight guidance as a co-simulation FMU (fmus/los_guidance.fmu): the ports and
parameters of eq (18)'s guidance FMU, so it takes its place in any scenario, plus the
lookahead distance and the cross-track error e as an output."""
from autopilot_fmu.guidance import ROUTE_PARAMETERS
from autopilot_fmu.guidance_slave import GuidanceSlave
from autopilot_fmu.los import LOOKAHEAD, LOSGuidance
from fmukit.slave import Var

_SAME = {v.name: v for v in GuidanceSlave.variables}
_ROUTE = ROUTE_PARAMETERS + ("R_accept",)


class LOSGuidanceSlave(GuidanceSlave):
    model_name = "los_guidance"
    description = ("Line-of-sight guidance: psi_d = pi_k - atan(e / Delta) on the active leg "
                   "(Fossen 2011, sec. 10.3.2), switching legs as eq (18)'s guidance does")
    variables = (
        _SAME["x"], _SAME["y"],
        Var.output("psi_d", "rad", "desired course, steering onto the active leg's line",
                   depends=("x", "y", "lookahead") + _ROUTE,
                   get=lambda s: s.model.psi_d(s.x, s.y)),
        Var.output("e", "m", "cross-track error from the active leg, positive to starboard",
                   depends=("x", "y") + _ROUTE, get=lambda s: s.model.cross_track(s.x, s.y)),
        _SAME["wp_index"],
        *(v for v in GuidanceSlave.variables if v.causality == "parameter"),
        Var.parameter("lookahead", LOOKAHEAD, "m", "lookahead distance Delta, > 0", 0.0, 1e6),
    )

    def build_model(self) -> LOSGuidance:
        legs = super().build_model()                        # the route, read and checked once
        return LOSGuidance(legs.points, legs.R_accept, self.lookahead)
