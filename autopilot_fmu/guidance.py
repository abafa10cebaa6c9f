"""Waypoint guidance, eq (18): the desired course is the bearing of the active leg.

    psi_d = atan2(y_{k+1} - y_k, x_{k+1} - x_k)

(x north, y east; atan2 resolves the quadrant that the printed arctan leaves open.)

Leg switching: the ship moves on to the next leg once it is inside the circle of
acceptance around the waypoint it is heading for, *or* once it has passed that
waypoint along the track (its along-track distance exceeds the leg's length).
A circle-only rule strands the ship whenever a turn leaves its cross-track offset
larger than R_accept: it never enters the circle and steers back to a waypoint
behind it. After the last waypoint the ship holds the last leg's course.

The guidance is memoryless apart from the index of the active leg, which only
moves forward. ``active_leg`` evaluates the switching rule without committing
it, so the output at a communication point is a pure function of the inputs there.
"""
from __future__ import annotations

import math

from fmukit.numerics import require_finite
from ship_fmu.data import Hull

PAPER_ROUTE = "0,0;30,0;60,25;90,25"
"""The reproduction route, m: the paper gives no waypoints (see docs/reproduction.md)."""

R_ACCEPT = 2.0 * Hull.L
"""Radius of the circle of acceptance, m: two ship lengths."""


def parse_waypoints(text: str) -> list[tuple[float, float]]:
    """'x0,y0;x1,y1;...' (m) -> [(x0, y0), ...]; ValueError naming 'waypoints'."""
    points = []
    for i, item in enumerate(part for part in text.split(";") if part.strip()):
        fields = item.split(",")
        try:
            if len(fields) != 2:
                raise ValueError
            x, y = float(fields[0]), float(fields[1])
        except ValueError:
            raise ValueError(f"parameter waypoints: point {i} is {item.strip()!r}, "
                             "expected 'x,y' with two numbers in m") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"parameter waypoints: point {i} ({x}, {y}) is not finite")
        if points and (x, y) == points[-1]:
            raise ValueError(f"parameter waypoints: points {i - 1} and {i} are both "
                             f"({x}, {y}); consecutive waypoints must differ")
        points.append((x, y))
    if len(points) < 2:
        raise ValueError(f"parameter waypoints needs at least two points 'x0,y0;x1,y1', "
                         f"got {text!r}")
    return points


class WaypointGuidance:
    """Desired course along a route of waypoints."""

    def __init__(self, waypoints: str = PAPER_ROUTE, R_accept: float = R_ACCEPT):
        if not (math.isfinite(R_accept) and R_accept > 0.0):
            raise ValueError(f"parameter R_accept must be finite and > 0, got {R_accept}")
        self.points = parse_waypoints(waypoints)
        self.R_accept = R_accept
        self.leg = 0                      # active leg: from points[leg] to points[leg + 1]
        self.finished = False
        self._last: tuple = (None, None)  # the rule's last evaluation (an FMU asks 3 times)

    def _reached(self, leg: int, x: float, y: float) -> bool:
        """Whether the ship is done with ``leg``: inside the circle or past its end."""
        (x0, y0), (x1, y1) = self.points[leg], self.points[leg + 1]
        dx, dy = x1 - x0, y1 - y0
        length = math.hypot(dx, dy)
        along = ((x - x0) * dx + (y - y0) * dy) / length
        return math.hypot(x1 - x, y1 - y) <= self.R_accept or along >= length

    def active_leg(self, x: float, y: float) -> tuple[int, bool]:
        """(leg, finished) at position (x, y), from the committed leg onward."""
        key = (x, y, self.leg, self.finished)
        if self._last[0] == key:
            return self._last[1]
        require_finite(x=x, y=y)
        leg, finished = self.leg, self.finished
        while not finished and self._reached(leg, x, y):
            if leg + 2 < len(self.points):
                leg += 1
            else:
                finished = True
        self._last = (key, (leg, finished))
        return leg, finished

    def course(self, leg: int) -> float:
        """Eq (18): bearing of a leg, rad in (-pi, pi]."""
        (x0, y0), (x1, y1) = self.points[leg], self.points[leg + 1]
        return math.atan2(y1 - y0, x1 - x0)

    def psi_d(self, x: float, y: float) -> float:
        """Desired course at (x, y), rad."""
        return self.course(self.active_leg(x, y)[0])

    def wp_index(self, x: float, y: float) -> int:
        """Index of the waypoint being steered to; len(points) once past the last."""
        leg, finished = self.active_leg(x, y)
        return len(self.points) if finished else leg + 1

    def update(self, x: float, y: float) -> None:
        """Commit leg switches at (x, y)."""
        self.leg, self.finished = self.active_leg(x, y)

    def snapshot(self) -> dict[str, int | bool]:
        return {"leg": self.leg, "finished": self.finished}

    def restore(self, snapshot: dict[str, int | bool]) -> None:
        self.leg, self.finished = int(snapshot["leg"]), bool(snapshot["finished"])
