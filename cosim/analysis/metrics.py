"""Figures of merit of a heading response and of a route: eq (19) cost, settling, overshoot,
rudder activity, cross-track error and route completion. SI units and radians throughout."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from autopilot_fmu.guidance import WaypointGuidance
from ..ensemble.exact import wrap


def heading_error(psi_d: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Delta psi_i = psi_d - psi, wrapped to (-pi, pi], rad (``fmukit.numerics.wrap`` of
    each sample, to the bit)."""
    return wrap(np.asarray(psi_d, dtype=float) - np.asarray(psi, dtype=float))


def cost_terms(psi_d: np.ndarray, psi: np.ndarray, delta: np.ndarray) -> tuple[float, float]:
    """(psi_E, sum delta^2) of eq (19), over the samples given, rad^2."""
    return float(np.sum(heading_error(psi_d, psi) ** 2)), float(np.sum(np.square(delta)))


def rms(values: np.ndarray) -> float:
    """Root mean square over the samples, in the values' unit."""
    return math.sqrt(float(np.mean(np.square(values))))


def peak(values: np.ndarray) -> float:
    """Largest magnitude over the samples, in the values' unit."""
    return float(np.max(np.abs(values)))


def settling_time(t: np.ndarray, error: np.ndarray, band: float) -> float:
    """First time after which |error| stays within band; inf if it never does."""
    outside = np.flatnonzero(np.abs(error) > band)
    if outside.size == 0:
        return float(t[0])
    if outside[-1] == len(t) - 1:
        return math.inf
    return float(t[outside[-1] + 1])


def overshoot(psi: np.ndarray, psi_start: float, psi_target: float) -> float:
    """Largest excursion beyond the target in the direction of the change, rad (>= 0)."""
    direction = math.copysign(1.0, psi_target - psi_start)
    return max(0.0, float(np.max(direction * (np.asarray(psi) - psi_target))))


RUDDER_DEADBAND = math.radians(0.5)
"""How far past amidships the rudder must go for a crossing to count, rad: a rudder that
dithers about zero by a rounding error (1e-15 rad in head seas, where sin(pi) leaves a
residue in the wave side force) or by a fraction of a degree does not reverse."""


def rudder_reversals_per_minute(t: np.ndarray, delta: np.ndarray,
                                deadband: float = RUDDER_DEADBAND) -> float:
    """Rudder reversals per minute: how often the rudder crosses from one side to the other,
    a crossing counted once the rudder is beyond ``deadband`` on the new side (hysteresis)."""
    delta = np.asarray(delta)
    sides = np.sign(delta)[np.abs(delta) > deadband]
    reversals = int(np.count_nonzero(sides[1:] != sides[:-1]))
    return reversals / ((t[-1] - t[0]) / 60.0)


def mean_abs_rate(t: np.ndarray, delta: np.ndarray) -> float:
    """Mean |d delta / dt| over the run, rad/s: the rudder's total travel over the time."""
    return float(np.sum(np.abs(np.diff(delta)))) / float(t[-1] - t[0])


def at_stops(delta: np.ndarray, delta_max: float) -> np.ndarray:
    """Whether the rudder is on its stops, |delta| >= delta_max, each sample."""
    return np.abs(np.asarray(delta)) >= delta_max * (1 - 1e-9)


def fraction_at_stops(delta: np.ndarray, delta_max: float) -> float:
    """Share of the samples (0 to 1) with the rudder on its stops (``at_stops``)."""
    return float(np.mean(at_stops(delta, delta_max)))


def cross_track_error(x: np.ndarray, y: np.ndarray, wp_index: np.ndarray,
                      points: Sequence[tuple[float, float]]) -> np.ndarray:
    """Signed distance of (x, y) from the line of the leg the guidance follows, m, positive
    to starboard of it (Fossen 2011, ch 10: e = -(x - x_k) sin alpha_k + (y - y_k) cos
    alpha_k, alpha_k the leg's course of eq 18).

    ``wp_index`` is the guidance's output: the waypoint steered to, so the leg runs from
    waypoint wp_index - 1 to wp_index; once past the last (wp_index = len(points)) the
    guidance holds the last leg's course, and the error is measured from that leg's line.
    """
    guidance = WaypointGuidance(points)
    leg = np.clip(np.asarray(wp_index, dtype=int) - 1, 0, len(points) - 2)
    alpha = np.array([guidance.course(k) for k in range(len(points) - 1)])[leg]
    start = np.asarray(points, dtype=float)[leg]
    return -(x - start[:, 0]) * np.sin(alpha) + (y - start[:, 1]) * np.cos(alpha)


@dataclass(frozen=True)
class RouteCompletion:
    """How close the track came to each waypoint of the route, against the guidance's
    circle of acceptance: a waypoint is reached if the ship came within R_accept of it.
    (The guidance also moves on once a waypoint is passed along track, so a ship set off
    its route can have every leg "done" without reaching a waypoint.)"""

    points: tuple[tuple[float, float], ...]     # the route, m
    closest: tuple[float, ...]                  # the track's closest approach to each, m
    R_accept: float                             # radius of the circle of acceptance, m

    @property
    def reached(self) -> tuple[bool, ...]:
        return tuple(d <= self.R_accept for d in self.closest)

    @property
    def count(self) -> int:
        """Waypoints reached, the start (the route's first point) included."""
        return sum(self.reached)

    @property
    def last_reached(self) -> bool:
        return self.reached[-1]


def route_completion(x: np.ndarray, y: np.ndarray, points: Sequence[tuple[float, float]],
                     R_accept: float) -> RouteCompletion:
    """Which waypoints of ``points`` the track (x, y) reached, within ``R_accept`` (m)."""
    closest = tuple(float(np.min(np.hypot(x - px, y - py))) for px, py in points)
    return RouteCompletion(tuple(map(tuple, points)), closest, R_accept)
