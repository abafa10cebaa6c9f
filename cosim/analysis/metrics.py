"""Figures of merit of a heading response: eq (19) cost, settling, overshoot, chattering."""
from __future__ import annotations

import math

import numpy as np

from fmukit.numerics import wrap


def heading_error(psi_d: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Delta psi_i = psi_d - psi, wrapped to (-pi, pi], rad."""
    return np.array([wrap(a - b) for a, b in zip(psi_d, psi)])


def cost_terms(psi_d: np.ndarray, psi: np.ndarray, delta: np.ndarray) -> tuple[float, float]:
    """(psi_E, sum delta^2) of eq (19), over the samples given, rad^2."""
    return float(np.sum(heading_error(psi_d, psi) ** 2)), float(np.sum(np.square(delta)))


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


def sign_reversals_per_minute(t: np.ndarray, delta: np.ndarray) -> float:
    """How often the rudder crosses from one side to the other, per minute."""
    signs = np.sign(delta)
    signs = signs[signs != 0]
    reversals = int(np.count_nonzero(signs[1:] != signs[:-1]))
    return reversals / ((t[-1] - t[0]) / 60.0)
