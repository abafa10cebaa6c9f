"""Steering gear: the rudder follows the command, clipped to +-delta_max, at a limited rate.

With the command held over a step the rudder angle is piecewise linear in time and known
exactly at any instant, so a run does not depend on how the step is cut. Defaults: 35 deg
stops, and 20 deg/s, the IMO full-scale rate (about 2.3 deg/s) Froude-scaled to 1:70.
"""
from __future__ import annotations

import math

DELTA_MAX = math.radians(35.0)
DELTA_RATE_MAX = math.radians(20.0)


def rudder_target(delta_c: float, delta_max: float = DELTA_MAX) -> float:
    """Where the rudder heads for: the command, within the stops."""
    return min(max(delta_c, -delta_max), delta_max)


class RudderMotion:
    """The rudder angle a time s >= 0 after it was delta0, with delta_c held: at the rate
    limit toward the target until ``reach`` (the kink, where the integrator cuts its
    step; 0 if the rudder is there already), then at the target."""

    __slots__ = ("delta0", "target", "velocity", "reach")

    def __init__(self, delta0: float, delta_c: float, delta_max: float = DELTA_MAX,
                 delta_rate_max: float = DELTA_RATE_MAX):
        self.delta0, self.target = delta0, rudder_target(delta_c, delta_max)
        error = self.target - delta0
        self.velocity = math.copysign(delta_rate_max, error)
        self.reach = abs(error) / delta_rate_max

    def __call__(self, s: float) -> float:
        return self.target if s >= self.reach else self.delta0 + self.velocity * s
