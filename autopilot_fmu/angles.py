"""Angle helpers: radians everywhere, errors wrapped to (-pi, pi]."""
import math


def wrap(angle: float) -> float:
    """The angle mod 2 pi in (-pi, pi]: the short way round."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped

