"""Steering gear: the rudder follows the command within +-delta_max at a limited rate, exact
at any instant; 20 deg/s is the IMO rate (2.3 deg/s) Froude-scaled to 1:70."""
import math

DELTA_MAX = math.radians(35.0)
DELTA_RATE_MAX = math.radians(20.0)


def rudder_target(delta_c: float, delta_max: float = DELTA_MAX) -> float:
    return min(max(delta_c, -delta_max), delta_max)


class RudderMotion:
    """The rudder angle s >= 0 after delta0, delta_c held: at the rate limit until
    ``reach`` (the kink, where the integrator cuts its step), then at the target."""
    __slots__ = ("delta0", "target", "velocity", "reach")

    def __init__(self, delta0: float, delta_c: float, delta_max: float = DELTA_MAX,
                 delta_rate_max: float = DELTA_RATE_MAX):
        self.delta0, self.target = delta0, rudder_target(delta_c, delta_max)
        error = self.target - delta0
        self.velocity = math.copysign(delta_rate_max, error)
        self.reach = abs(error) / delta_rate_max if delta_rate_max else math.inf  # 0: stuck

    def __call__(self, s: float) -> float:
        return self.target if s >= self.reach else self.delta0 + self.velocity * s
