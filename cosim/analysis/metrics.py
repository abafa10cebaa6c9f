"""Figures of merit of a heading response and of a route, SI units and radians; eq (19):
J = psi_E + lambda sum(delta^2), lambda calibrated once on calm_pd and held (test_cosim.py)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from autopilot_fmu.guidance import leg_offsets

from ..core.recording import Recording
from ..ensemble.exact import wrap

RUDDER_DEADBAND = math.radians(0.5)   # past amidships for a crossing to count: no dither
LAMBDA = 1.8649470947066942     # psi_E / sum(delta^2) of calm_pd: 100.175 / 53.715 rad^2


def heading_error(psi_d: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """psi_d - psi wrapped to (-pi, pi], rad, to the bit as the FMUs wrap it."""
    return wrap(np.asarray(psi_d, dtype=float) - np.asarray(psi, dtype=float))


def stage_cost(psi_d: np.ndarray, psi: np.ndarray, delta: np.ndarray,
               lam: float = LAMBDA) -> np.ndarray:
    """Each sample's share of eq (19), (psi_d - psi)^2 + lambda delta^2: summed, J."""
    return heading_error(psi_d, psi) ** 2 + lam * np.square(delta)


def cost_terms(psi_d: np.ndarray, psi: np.ndarray, delta: np.ndarray) -> tuple[float, float]:
    """(psi_E, sum delta^2) of eq (19), over the samples given, rad^2."""
    return float(np.sum(heading_error(psi_d, psi) ** 2)), float(np.sum(np.square(delta)))


@dataclass(frozen=True)
class Cost:
    """Eq (19) over the recorded samples."""
    psi_E: float
    sum_delta2: float
    lam: float

    @property
    def delta_E(self) -> float:
        return self.lam * self.sum_delta2

    @property
    def J(self) -> float:
        return self.psi_E + self.delta_E


def cost(recording: Recording, lam: float = LAMBDA) -> Cost:
    """Eq (19) with Delta psi = psi_d - psi (wrapped) and delta the actual rudder."""
    return Cost(*cost_terms(recording["guidance.psi_d"], recording["ship.psi"],
                            recording["ship.delta"]), lam)


def rms(values: np.ndarray) -> float:
    return math.sqrt(float(np.mean(np.square(values))))


def peak(values: np.ndarray) -> float:
    return float(np.max(np.abs(values)))


def settling_time(t: np.ndarray, error: np.ndarray, band: float) -> float:
    """First time after which |error| stays within band; inf if never."""
    outside = np.flatnonzero(np.abs(error) > band)
    if outside.size == 0:
        return float(t[0])
    return math.inf if outside[-1] == len(t) - 1 else float(t[outside[-1] + 1])


def course_settling(t: np.ndarray, psi_d: np.ndarray, psi: np.ndarray, wp_index: np.ndarray,
                    share: float = 0.05) -> float:
    """Mean time, s, from each leg switch that turns psi_d by over 1 deg until |psi_d - psi|
    stays within ``share`` of that turn until the next switch (the rest of the leg if it
    never does); NaN if there is none."""
    error = heading_error(psi_d, psi)
    switches = np.flatnonzero(np.diff(wp_index) != 0) + 1
    turns = np.abs(heading_error(psi_d[switches], psi_d[switches - 1]))
    ends = [*switches[1:], len(t)]
    times = [min(settling_time(t[a:b], error[a:b], share * turn), t[b - 1]) - t[a]
             for a, b, turn in zip(switches, ends, turns) if turn > math.radians(1.0)]
    return float(np.mean(times)) if times else math.nan


def overshoot(psi: np.ndarray, psi_start: float, psi_target: float) -> float:
    """Largest excursion beyond the target in the direction of the change, rad (>= 0)."""
    direction = math.copysign(1.0, psi_target - psi_start)
    return max(0.0, float(np.max(direction * (np.asarray(psi) - psi_target))))


def rudder_reversals_per_minute(t: np.ndarray, delta: np.ndarray) -> float:
    """Rudder crossings per minute, each counted once beyond the deadband on the new side."""
    sides = np.sign(delta)[np.abs(delta) > RUDDER_DEADBAND]
    return int(np.count_nonzero(sides[1:] != sides[:-1])) / ((t[-1] - t[0]) / 60.0)


def mean_abs_rate(t: np.ndarray, delta: np.ndarray) -> float:
    """Mean |d delta / dt|, rad/s: the rudder's total travel over the time."""
    return float(np.sum(np.abs(np.diff(delta)))) / float(t[-1] - t[0])


def at_stops(delta: np.ndarray, delta_max: float) -> np.ndarray:
    return np.abs(np.asarray(delta)) >= delta_max * (1 - 1e-9)


def fraction_at_stops(delta: np.ndarray, delta_max: float) -> float:
    return float(np.mean(at_stops(delta, delta_max)))


def cross_track_error(x: np.ndarray, y: np.ndarray, wp_index: np.ndarray,
                      points: Sequence[tuple[float, float]]) -> np.ndarray:
    """e of the leg to ``wp_index`` (past the last: the last leg), m, positive to starboard
    (``leg_offsets``, as LOS guidance computes it)."""
    leg = np.clip(np.asarray(wp_index, dtype=int) - 1, 0, len(points) - 2)
    start, end = (np.asarray(points, dtype=float)[k] for k in (leg, leg + 1))
    (x0, y0), (dx, dy) = start.T, (end - start).T
    lengths = np.array([math.hypot(x1 - xa, y1 - ya) for (xa, ya), (x1, y1) in
                        zip(points[:-1], points[1:])])
    return leg_offsets(x, y, x0, y0, dx, dy, lengths[leg])[0]


@dataclass(frozen=True)
class RouteCompletion:
    """How close the track came to each waypoint, reached if within R_accept."""
    points: tuple[tuple[float, float], ...]     # the route, m
    closest: tuple[float, ...]                  # the track's closest approach to each, m
    R_accept: float                             # radius of the circle of acceptance, m

    @property
    def reached(self) -> tuple[bool, ...]:
        return tuple(d <= self.R_accept for d in self.closest)

    @property
    def count(self) -> int:                 # waypoints reached, the start included
        return sum(self.reached)

    @property
    def last_reached(self) -> bool:
        return self.reached[-1]


def route_completion(x: np.ndarray, y: np.ndarray, points: Sequence[tuple[float, float]],
                     R_accept: float) -> RouteCompletion:
    closest = tuple(float(np.min(np.hypot(x - px, y - py))) for px, py in points)
    return RouteCompletion(tuple(map(tuple, points)), closest, R_accept)
