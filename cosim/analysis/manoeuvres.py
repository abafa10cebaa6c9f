"""The figures of a standard manoeuvre from its trajectory (MSC.137(76) 4.2, MSC/Circ.1053), SI
units and radians (a positive rudder turns to port), and the 5.3 criteria for ships of 100 m and
over: on this 1:70 model through Froude scaling (ship lengths the same, L/V times sqrt(70))."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ship_fmu.data import Hull

from ..core.recording import Recording
from .seastate import SCALE

TURNING_RUDDER = math.radians(35.0)   # 4.2.2: 35 deg, or the largest permissible
STANDARD = "MSC.137(76)"
ADVANCE_LIMIT = 4.5                   # ship lengths, 5.3.1
TACTICAL_DIAMETER_LIMIT = 5.0         # ship lengths, 5.3.1
INITIAL_TURNING_LIMIT = 2.5           # ship lengths, 5.3.2
FIRST_OVERSHOOT_20_LIMIT = math.radians(25.0)   # 5.3.3.3
_SAME_ANGLE = 1e-6                    # rad: a test's angles match the standard's within this


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


def steady_circle(x: np.ndarray, y: np.ndarray, psi: np.ndarray) -> tuple[float, float, float]:
    """(x, y) of the centre and the diameter, m, of the least-squares circle (Kasa's fit) of
    the last lap; NaNs unless it turned 540 deg."""
    if abs(psi[-1] - psi[0]) < 3.0 * math.pi:
        return math.nan, math.nan, math.nan
    lap = np.abs(psi[-1] - psi) <= 2.0 * math.pi
    x, y = x[lap], y[lap]
    (cx, cy, c), *_ = np.linalg.lstsq(np.column_stack([2.0 * x, 2.0 * y, np.ones_like(x)]),
                                      x * x + y * y, rcond=None)
    return float(cx), float(cy), 2.0 * math.sqrt(c + cx * cx + cy * cy)


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


@dataclass(frozen=True)
class Criterion:
    """One MSC.137(76) criterion: a figure of the run, its limit and the clause setting it."""
    figure: str      # what is judged, in the standard's words
    value: float     # in ``unit``; NaN if the run never produced it (a turn never checked)
    limit: float     # the largest value that passes, in ``unit``
    unit: str        # "L" (ship lengths) or "rad"
    clause: str      # of MSC.137(76)
    basis: str = ""  # what set the limit, if it depends on the ship (L/V)
    missing: str = "not reached in the run"   # why ``value`` is NaN, when it is
    at_least: bool = False   # ``value`` is a lower bound: the run ended before the figure

    @property
    def verdict(self) -> str:
        """PASS, FAIL, or OPEN: a figure not reached, or only a lower bound within the limit."""
        if self.value > self.limit:
            return "FAIL"
        return "OPEN" if self.at_least or math.isnan(self.value) else "PASS"


def length_over_speed(length: float, speed: float, scale: float = SCALE) -> float:
    """L/V at full scale, s, of a model of ``length`` m at ``speed`` m/s (Froude)."""
    return math.sqrt(scale) * length / speed


def overshoot_limits(lv: float) -> tuple[float, float]:
    """(first, second) 10/10 overshoot limits, rad, for L/V in s at full scale (5.3.3.1-2)."""
    lv = min(max(lv, 10.0), 30.0)          # 10 and 25 deg below 10 s, 20 and 40 above 30 s
    return math.radians(5.0 + 0.5 * lv), math.radians(17.5 + 0.75 * lv)


def _is(angle: float, degrees: float) -> bool:
    return abs(angle - math.radians(degrees)) < _SAME_ANGLE


def turning_circle_criteria(tc: TurningCircle, delta: float,
                            delta_max: float) -> tuple[Criterion, ...]:
    """MSC.137(76) 5.3.1, at 35 deg rudder or the gear's largest; none for another angle."""
    if abs(delta - min(TURNING_RUDDER, delta_max)) >= _SAME_ANGLE:
        return ()
    return (Criterion("advance", tc.advance / Hull.L, ADVANCE_LIMIT, "L", "5.3.1",
                      missing="none: the heading never changed by 90 deg"),
            Criterion("tactical diameter", tc.tactical_diameter / Hull.L,
                      TACTICAL_DIAMETER_LIMIT, "L", "5.3.1",
                      missing="none: the heading never changed by 180 deg"))


def zigzag_criteria(zz: ZigZagResult, delta: float, approach_speed: float
                    ) -> tuple[Criterion, ...]:
    """MSC.137(76) 5.3.2-3 for a 10/10 or a 20/20 zig-zag; none for another test."""
    if _is(delta, 10.0) and _is(zz.psi_switch, 10.0):
        lv = length_over_speed(Hull.L, approach_speed)
        first, second = overshoot_limits(lv)
        basis = (f"L/V = {lv:.1f} s at full scale (1:{SCALE:g}; "
                 f"{Hull.L / approach_speed:.2f} s for the model)")
        return (Criterion("initial turning: distance by 10 deg heading change",
                          zz.initial_turning_distance / Hull.L, INITIAL_TURNING_LIMIT, "L",
                          "5.3.2", missing="none: the heading never changed by 10 deg"),
                _overshoot_criterion(zz, 1, first, "5.3.3.1", basis),
                _overshoot_criterion(zz, 2, second, "5.3.3.2", basis))
    if _is(delta, 20.0) and _is(zz.psi_switch, 20.0):
        return (_overshoot_criterion(zz, 1, FIRST_OVERSHOOT_20_LIMIT, "5.3.3.3"),)
    return ()


def _overshoot_criterion(zz: ZigZagResult, n: int, limit: float, clause: str,
                         basis: str = "") -> Criterion:
    value, at_least = zz.overshoot_bound(n)
    return Criterion(f"{('first', 'second')[n - 1]} overshoot", value, limit, "rad", clause,
                     basis, "none: the run ended before that turn", at_least)


@dataclass(frozen=True)
class Assessment:
    """A recorded manoeuvre: its figures and the criteria that apply to it."""
    figures: TurningCircle | ZigZagResult
    criteria: tuple[Criterion, ...]
    delta: float                # rad, the test's rudder angle


def turning_circle_of(run: Recording) -> Assessment:
    tc = turning_circle_figures(*(run[f"ship.{n}"] for n in ("x", "y", "psi", "u", "v", "r")))
    p, delta = run.meta["parameters"], run.meta["parameters"]["program"]["delta"]
    return Assessment(tc, turning_circle_criteria(tc, delta, p["ship"]["delta_max"]), delta)


def zigzag_of(run: Recording) -> Assessment:
    program = run.meta["parameters"]["program"]
    zz = zigzag_figures(run["ship.psi"], run["program.reversals"], program["psi_switch"],
                        run.t, run["ship.x"], run["ship.y"])
    approach = math.hypot(run["ship.u"][0], run["ship.v"][0])
    return Assessment(zz, zigzag_criteria(zz, program["delta"], approach), program["delta"])
