"""Lookahead-based line-of-sight guidance (Fossen 2011, sec. 10.3.2): on the active leg,
switched as eq (18)'s guidance switches, psi_d = pi_k - atan(e / Delta), with pi_k the leg's
course (eq 18), e the cross-track error and Delta the lookahead distance. Eq (18) steers the
leg's course wherever the ship is; LOS steers back onto the leg's line."""
import math
from collections.abc import Sequence

from autopilot_fmu.guidance import PAPER_ROUTE, R_ACCEPT, WaypointGuidance, leg_offsets
from fmukit.numerics import wrap
from ship_fmu.data import Hull

LOOKAHEAD = 4.0 * Hull.L     # m, Delta: the PD of eq (20), which turns in about a minute,
                             # follows waves_pd's legs closest with it (docs/fmus.md)


class LOSGuidance(WaypointGuidance):
    """``WaypointGuidance`` whose desired course steers onto the active leg's line."""

    def __init__(self, waypoints: str | Sequence[tuple[float, float]] = PAPER_ROUTE,
                 R_accept: float = R_ACCEPT, lookahead: float = LOOKAHEAD):
        super().__init__(waypoints, R_accept)
        if not (math.isfinite(lookahead) and lookahead > 0.0):
            raise ValueError(f"parameter lookahead must be finite and > 0, got {lookahead}")
        self.lookahead = lookahead

    def cross_track(self, x: float, y: float) -> float:
        """e, m: from the active leg's line, positive to starboard of it (Fossen's sign)."""
        leg = self.active_leg(x, y)[0]
        (x0, y0), (x1, y1) = self.points[leg], self.points[leg + 1]
        dx, dy = x1 - x0, y1 - y0
        return leg_offsets(x, y, x0, y0, dx, dy, math.hypot(dx, dy))[0]

    def psi_d(self, x: float, y: float) -> float:
        leg = self.active_leg(x, y)[0]
        return wrap(self.course(leg) - math.atan(self.cross_track(x, y) / self.lookahead))
