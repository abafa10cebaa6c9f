"""Angle helpers: radians everywhere, errors wrapped to (-pi, pi]."""
import math


def wrap(angle: float) -> float:
    """The angle mod 2 pi in (-pi, pi]: the short way round."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def require_finite(**values: float) -> None:
    """Raise ValueError naming the first input that is NaN or infinite."""
    for name, value in values.items():
        if not math.isfinite(value):
            raise ValueError(f"input {name} = {value} is not finite")
