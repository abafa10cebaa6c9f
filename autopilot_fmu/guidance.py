"""Waypoint guidance, eq (18): psi_d = atan2(y_{k+1} - y_k, x_{k+1} - x_k), x north. The
next leg starts inside the circle of acceptance *or* once past the waypoint along the track
(a circle-only rule strands a ship turning wide); past the last, the last course holds."""
import math
from collections.abc import Mapping, Sequence
from typing import Any

from fmukit.numerics import require_finite
from ship_fmu.data import Hull

PAPER_ROUTE = "0,0;30,0;60,25;90,25"    # m; the paper gives none (docs/reproduction.md)
R_ACCEPT = 2.0 * Hull.L                  # m, radius of the circle of acceptance
MAX_WAYPOINTS = 16                       # points of the numeric route: wp0_x ... wp15_y
COORDINATES = tuple(f"wp{i}_{axis}" for i in range(MAX_WAYPOINTS) for axis in "xy")
ROUTE_PARAMETERS = ("waypoints", "n_waypoints", *COORDINATES)   # what ``route`` reads


def _checked(points: list[tuple[float, float]], what: str) -> list[tuple[float, float]]:
    """``points`` if finite, no two consecutive alike; ValueError naming ``what``."""
    for i, (x, y) in enumerate(points):
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"parameter {what}: point {i} ({x}, {y}) is not finite")
        if i and (x, y) == points[i - 1]:
            raise ValueError(f"parameter {what}: points {i - 1} and {i} are both "
                             f"({x}, {y}); consecutive waypoints must differ")
    return points


def parse_waypoints(text: str) -> list[tuple[float, float]]:
    """'x0,y0;x1,y1;...' (m) -> [(x0, y0), ...]; ValueError naming 'waypoints'."""
    points = []
    for i, item in enumerate(part for part in text.split(";") if part.strip()):
        try:
            x, y = map(float, item.split(","))
        except ValueError:
            raise ValueError(f"parameter waypoints: point {i} is {item.strip()!r}, "
                             "expected 'x,y' with two numbers in m") from None
        points.append((x, y))
    if len(points) < 2:
        raise ValueError(f"parameter waypoints needs at least two points 'x0,y0;x1,y1', "
                         f"got {text!r}")
    return _checked(points, "waypoints")


def numeric_route(text: str) -> dict[str, int | float]:
    """The route 'x0,y0;...' as n_waypoints and wp<i>_x, wp<i>_y (others unset)."""
    points = parse_waypoints(text)
    if len(points) > MAX_WAYPOINTS:
        raise ValueError(f"the route {text!r} has {len(points)} points; its numeric form "
                         f"holds at most {MAX_WAYPOINTS}")
    values: dict[str, int | float] = {"n_waypoints": len(points)}
    values.update(zip(COORDINATES, [c for point in points for c in point]))
    return values


def route(parameters: Mapping[str, Any]) -> list[tuple[float, float]]:
    """The route of the guidance's parameters by name (absent: defaults): the String if
    n_waypoints = 0, else wp0 .. wp<n-1>; ValueError naming them if they contradict."""
    text = parameters.get("waypoints", PAPER_ROUTE)
    count = parameters.get("n_waypoints", 0)
    coordinates = [float(parameters.get(name, 0.0)) for name in COORDINATES]
    for name, value in list(zip(COORDINATES, coordinates))[2 * count:]:
        if value != 0.0:
            uses = (f"uses only wp0 .. wp{count - 1}" if count else
                    "takes the route from the String waypoints")
            raise ValueError(f"parameter {name} = {value} is set, but n_waypoints = {count} "
                             f"{uses}")
    if count == 0:
        return parse_waypoints(text)
    if not 2 <= count <= MAX_WAYPOINTS:
        raise ValueError(f"parameter n_waypoints = {count}: a route needs 2 to "
                         f"{MAX_WAYPOINTS} points (0: the String waypoints)")
    points = _checked(list(zip(coordinates[0:2 * count:2], coordinates[1:2 * count:2])),
                      f"wp0_x .. wp{count - 1}_y")
    if text != PAPER_ROUTE and parse_waypoints(text) != points:
        raise ValueError(f"parameters waypoints = {text!r} and n_waypoints = {count} with "
                         "wp<i>_x, wp<i>_y give two different routes; set one of them")
    return points


def leg_offsets(x: Any, y: Any, x0: Any, y0: Any, dx: Any, dy: Any, length: Any
                ) -> tuple[Any, Any]:
    """(e, along) of (x, y) from the leg that starts at (x0, y0) and runs (dx, dy), of
    ``length``: the cross-track error, positive to starboard (Fossen 2011, ch. 10), and the
    distance along the leg, m. Floats, or arrays (the batch kernel, metrics): the same bits."""
    return ((y - y0) * dx - (x - x0) * dy) / length, ((x - x0) * dx + (y - y0) * dy) / length


class WaypointGuidance:
    """Desired course along a route of waypoints."""

    def __init__(self, waypoints: str | Sequence[tuple[float, float]] = PAPER_ROUTE,
                 R_accept: float = R_ACCEPT):
        if not (math.isfinite(R_accept) and R_accept > 0.0):
            raise ValueError(f"parameter R_accept must be finite and > 0, got {R_accept}")
        self.points = (parse_waypoints(waypoints) if isinstance(waypoints, str)
                       else _checked(list(waypoints), "waypoints"))
        self.R_accept = R_accept
        self.leg = 0                      # active leg: from points[leg] to points[leg + 1]
        self.finished = False

    def _reached(self, leg: int, x: float, y: float) -> bool:
        (x0, y0), (x1, y1) = self.points[leg], self.points[leg + 1]
        dx, dy = x1 - x0, y1 - y0
        length = math.hypot(dx, dy)
        along = leg_offsets(x, y, x0, y0, dx, dy, length)[1]
        return math.hypot(x1 - x, y1 - y) <= self.R_accept or along >= length

    def active_leg(self, x: float, y: float) -> tuple[int, bool]:
        """(leg, finished) at position (x, y), from the committed leg onward."""
        require_finite(x=x, y=y)
        leg, finished = self.leg, self.finished
        while not finished and self._reached(leg, x, y):
            if leg + 2 < len(self.points):
                leg += 1
            else:
                finished = True
        return leg, finished

    def course(self, leg: int) -> float:
        """Eq (18): bearing of a leg, rad in (-pi, pi]."""
        (x0, y0), (x1, y1) = self.points[leg], self.points[leg + 1]
        return math.atan2(y1 - y0, x1 - x0)

    def psi_d(self, x: float, y: float) -> float:
        return self.course(self.active_leg(x, y)[0])

    def wp_index(self, x: float, y: float) -> int:
        """Index of the waypoint being steered to; len(points) once past the last."""
        leg, finished = self.active_leg(x, y)
        return len(self.points) if finished else leg + 1

    def update(self, x: float, y: float) -> None:
        self.leg, self.finished = self.active_leg(x, y)

    def snapshot(self) -> dict[str, int | bool]:
        return {"leg": self.leg, "finished": self.finished}

    def restore(self, snapshot: dict[str, int | bool]) -> None:
        self.leg, self.finished = int(snapshot["leg"]), bool(snapshot["finished"])
