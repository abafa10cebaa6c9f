"""Numerical rules every model here follows: finite inputs, bounded sub-stepping (a huge
step is refused instead of hanging the host), angle differences wrapped the short way round."""
from __future__ import annotations

import math

from .refusals import Refused

MAX_SUBSTEPS = 100_000     # integration steps one communication step may take


def wrap(angle: float) -> float:
    """The angle mod 2 pi in (-pi, pi]: the short way round."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def require_finite(**values: float) -> None:
    """Raise Refused (a ValueError) naming the first input that is NaN or infinite."""
    for name, value in values.items():
        if not math.isfinite(value):
            raise Refused(f"input {name} = {value} is not finite", "nonfinite_input", name)


def substeps(h: float, h_max: float, what: str) -> int:
    """Equal integration steps that cut a communication step h into pieces <= h_max."""
    n = max(1, math.ceil(h / h_max - 1e-9))
    if n > MAX_SUBSTEPS:
        raise ValueError(f"a communication step of {h} s needs {n} RK4 steps {what}; "
                         f"at most {MAX_SUBSTEPS} are taken per step")
    return n
