"""The scalar models' ``math`` functions on arrays, to the bit: ``np.hypot`` and ``np.tanh``
round otherwise on some inputs, so these call ``math`` per element; ``remainder`` rebuilds
CPython's from the exact ``np.fmod``."""
from __future__ import annotations

import math

import numpy as np

hypot = np.vectorize(math.hypot, otypes=[float])
tanh = np.vectorize(math.tanh, otypes=[float])


def remainder(x: np.ndarray, y: float) -> np.ndarray:
    """``math.remainder(x, y)`` for a finite y > 0, as CPython's ``m_remainder``."""
    absx = np.abs(x)
    with np.errstate(invalid="ignore"):          # an infinite x: NaN, as math.remainder
        m = np.fmod(absx, y)
    c = y - m
    r = np.where(m < c, m, -c)
    tie = m == c
    if tie.any():                        # half way: the even multiple of y
        r = np.where(tie, m - 2.0 * np.fmod(0.5 * (absx - m), y), r)
    r = np.copysign(1.0, x) * r
    return np.where(np.isfinite(x), r, np.nan)


def wrap(angle: np.ndarray) -> np.ndarray:
    """``fmukit.numerics.wrap`` of each element: the angle mod 2 pi in (-pi, pi]."""
    wrapped = remainder(angle, 2.0 * math.pi)
    return np.where(wrapped == -math.pi, math.pi, wrapped)
