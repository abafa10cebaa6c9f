"""The figures of a standard manoeuvre from its trajectory (MSC.137(76) 4.2, MSC/Circ.1053),
in SI units and radians; a positive rudder turns the ship to port."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TURNING_RUDDER = math.radians(35.0)   # 4.2.2: 35 deg, or the largest permissible


@dataclass(frozen=True)
class TurningCircle:
    """A turning circle's figures; NaN where the run's heading never changed enough."""
    advance: float               # m, along the approach course at 90 deg heading change
    transfer: float              # m, across the approach course at 90 deg
    tactical_diameter: float     # m, across the approach course at 180 deg
    steady_yaw_rate: float       # rad/s, signed, at the end of the run
    steady_speed: float          # m/s, sqrt(u^2 + v^2) at the end of the run
    steady_diameter: float = math.nan   # m, of a circle fitted to the last lap of the track
    approach_speed: float = math.nan    # m/s, sqrt(u^2 + v^2) at the rudder order
    drift_angle: float = math.nan       # rad, atan2(v, u) at the end of the run
    course_change_at_tactical: float = math.nan  # rad, where the heading has changed 180 deg
    heading_change: float = math.nan    # rad, the largest |psi - psi[0]| of the run

    @property
    def diameter_from_rates(self) -> float:        # 2 U / |r| of the steady turn, m
        return 2.0 * self.steady_speed / abs(self.steady_yaw_rate)


@dataclass(frozen=True)
class Overshoot:
    """A checked turn: how far the heading went beyond the switching angle, and when."""
    angle: float     # rad, beyond the switching angle
    time: float      # s, when the heading deviation peaked
    heading: float   # rad, the heading deviation at the peak, signed


@dataclass(frozen=True)
class ZigZagResult:
    """A delta/psi_switch zig-zag's figures, as MSC/Circ.1053 draws them."""
    reversals: int                         # rudder reversals the test reached
    psi_switch: float = math.nan           # rad, heading deviation that reverses the rudder
    overshoots: tuple[Overshoot, ...] = ()  # one per checked turn, in order
    executes: tuple[float, ...] = ()       # s, the rudder orders: the first, then reversals
    initial_turning_distance: float = math.nan  # m travelled until |psi| reached psi_switch
    running: Overshoot | None = None       # so far, of a 1st or 2nd turn still going at the end

    @property
    def checked(self) -> bool:
        return len(self.overshoots) >= 2

    def overshoot_bound(self, n: int) -> tuple[float, bool]:
        """(angle, at_least): measured, a lower bound if the run ended in that turn, or NaN."""
        if len(self.overshoots) >= n:
            return self.overshoots[n - 1].angle, False
        if self.running is not None and len(self.overshoots) == n - 1:
            return self.running.angle, True
        return math.nan, False

    @property
    def initial_turning_time(self) -> float:       # s, from the first execute to the second
        return self.executes[1] - self.executes[0] if len(self.executes) > 1 else math.nan

    @property
    def time_to_check_yaw(self) -> float:          # s, second execute to the first overshoot
        return self.overshoots[0].time - self.executes[1] if self.overshoots else math.nan

    @property
    def period(self) -> float:                     # s, one cycle: second execute to the fourth
        return self.executes[3] - self.executes[1] if len(self.executes) > 3 else math.nan


def _first_reaching(level: np.ndarray, target: float, *series: np.ndarray) -> list[float]:
    i = int(np.argmax(level >= target))
    if level[i] < target:
        return [math.nan] * len(series)
    if i == 0:
        return [float(s[0]) for s in series]
    w = (target - level[i - 1]) / (level[i] - level[i - 1])
    return [float(s[i - 1] + w * (s[i] - s[i - 1])) for s in series]


def at_heading_change(psi: np.ndarray, target: float, *series: np.ndarray) -> list[float]:
    """Each series, interpolated where the heading first changed by ``target`` from psi[0]."""
    return _first_reaching(np.abs(psi - psi[0]), target, *series)


def approach_frame(x: np.ndarray, y: np.ndarray, psi0: float) -> tuple[np.ndarray, np.ndarray]:
    """(along, across to starboard of) the approach course psi0 from the first point, m."""
    dx, dy, c, s = x - x[0], y - y[0], math.cos(psi0), math.sin(psi0)
    return dx * c + dy * s, -dx * s + dy * c


def fitted_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """(x, y) of the centre and the diameter of the least-squares circle (Kasa's fit), m."""
    A = np.column_stack([2.0 * x, 2.0 * y, np.ones_like(x)])
    (cx, cy, c), *_ = np.linalg.lstsq(A, x * x + y * y, rcond=None)
    return float(cx), float(cy), 2.0 * math.sqrt(c + cx * cx + cy * cy)


def steady_circle(x: np.ndarray, y: np.ndarray, psi: np.ndarray) -> tuple[float, float, float]:
    """``fitted_circle`` of the last lap; NaNs unless it turned 540 deg."""
    if abs(psi[-1] - psi[0]) < 3.0 * math.pi:
        return math.nan, math.nan, math.nan
    lap = np.abs(psi[-1] - psi) <= 2.0 * math.pi
    return fitted_circle(x[lap], y[lap])


def turning_circle_figures(x, y, psi, u, v, r) -> TurningCircle:
    """Turning-circle figures of a run from steady straight running along psi[0]."""
    x, y, psi, u, v, r = map(np.asarray, (x, y, psi, u, v, r))
    along, across = approach_frame(x, y, float(psi[0]))
    advance, transfer = at_heading_change(psi, math.pi / 2, along, across)
    _, tactical, u180, v180 = at_heading_change(psi, math.pi, along, across, u, v)
    turn = math.copysign(math.pi, psi[-1] - psi[0])
    course = turn + math.atan2(v180, u180) - math.atan2(v[0], u[0])
    return TurningCircle(advance=advance, transfer=abs(transfer), tactical_diameter=abs(tactical),
                         steady_yaw_rate=float(r[-1]), steady_speed=float(math.hypot(u[-1], v[-1])),
                         steady_diameter=steady_circle(x, y, psi)[2],
                         approach_speed=float(math.hypot(u[0], v[0])),
                         drift_angle=float(math.atan2(v[-1], u[-1])),
                         course_change_at_tactical=abs(course),
                         heading_change=float(np.abs(psi - psi[0]).max()))


def zigzag_figures(psi, reversals, psi_switch: float, t, x, y) -> ZigZagResult:
    """A zig-zag's figures from heading deviation psi and the program's reversal count; an
    overshoot counts once the heading turned back, else it is ``running`` (a lower bound)."""
    psi, reversals, t = np.asarray(psi), np.asarray(reversals), np.asarray(t)
    reached = int(reversals.max())

    def peak(n: int) -> tuple[Overshoot, bool]:
        turn = np.flatnonzero(reversals == n)
        k = turn[np.argmax(np.abs(psi[turn]))]
        return Overshoot(float(abs(psi[k]) - psi_switch), float(t[k]), float(psi[k])), \
            bool(k < turn[-1])
    overshoots = [peak(n)[0] for n in range(1, reached)]
    running = None
    if 0 < reached < 3:                       # the run ended in the first or second turn
        last, checked = peak(reached)
        overshoots, running = (overshoots + [last], None) if checked else (overshoots, last)
    executes = tuple(float(t[k]) for k in [0, *(np.flatnonzero(np.diff(reversals)) + 1)])
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])
    distance, = _first_reaching(np.abs(psi), psi_switch, travelled)
    return ZigZagResult(reached, psi_switch, tuple(overshoots), executes, distance, running)

