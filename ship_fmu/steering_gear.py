"""Steering gear: the actual rudder angle follows the command at a limited rate.

The command is clipped to +-delta_max (rudder stops) and the rudder moves toward it
at most at delta_rate_max. With the command held over a communication step, the
rudder angle is piecewise linear in time, and ``rudder_angle`` returns it exactly
at any instant of the step: the integrator samples it at its stages, and a run
does not depend on how the step is cut.

Defaults: 35 deg stops, the common choice for this model, and 20 deg/s, the IMO
full-scale steering rate (SOLAS: 35 deg port to 30 deg starboard in 28 s, about
2.3 deg/s) Froude-scaled to 1:70 (time scales with sqrt(70), rates by 8.4).
"""
from __future__ import annotations

import math

DELTA_MAX = math.radians(35.0)
DELTA_RATE_MAX = math.radians(20.0)


def rudder_target(delta_c: float, delta_max: float = DELTA_MAX) -> float:
    """Where the rudder heads for: the command, within the stops."""
    return min(max(delta_c, -delta_max), delta_max)


class RudderMotion:
    """The rudder angle as a function of the time s >= 0 since it was delta0, with
    delta_c held: at the rate limit toward the target until ``reach``, then at the
    target. ``reach`` is the kink of that function (0 if the rudder is there already):
    the vessel's integrator cuts its steps there."""

    __slots__ = ("delta0", "target", "velocity", "reach")

    def __init__(self, delta0: float, delta_c: float, delta_max: float = DELTA_MAX,
                 delta_rate_max: float = DELTA_RATE_MAX):
        self.delta0, self.target = delta0, rudder_target(delta_c, delta_max)
        error = self.target - delta0
        self.velocity = math.copysign(delta_rate_max, error)
        self.reach = abs(error) / delta_rate_max

    def __call__(self, s: float) -> float:
        return self.target if s >= self.reach else self.delta0 + self.velocity * s


def rudder_angle(delta0: float, delta_c: float, s: float,
                 delta_max: float = DELTA_MAX,
                 delta_rate_max: float = DELTA_RATE_MAX) -> float:
    """Rudder angle a time s >= 0 after it was delta0, with delta_c held."""
    return RudderMotion(delta0, delta_c, delta_max, delta_rate_max)(s)
