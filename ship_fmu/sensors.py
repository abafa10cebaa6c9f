"""The ship's instruments: a gyrocompass and a rate gyro with bias, white noise and
quantisation, and a GNSS receiver with white position noise. Each step's draws are seeded
by (seed, step), so that a saved and restored state goes on as it would have; with no noise,
bias or quantisation each reads its true value exactly."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fmukit.numerics import require_finite


def quantised(value: float, resolution: float) -> float:
    """``value`` to the nearest multiple of ``resolution``; as it is if that is 0, or finer
    than a float tells apart (found by the fuzzer: 5e-324)."""
    steps = value / resolution if resolution else math.inf
    return resolution * round(steps) if abs(steps) < 2.0**52 else value


@dataclass
class Sensors:
    psi_bias: float = 0.0           # rad
    psi_noise: float = 0.0          # rad, standard deviation of the white noise
    psi_resolution: float = 0.0     # rad, a reading's step (0: none)
    r_bias: float = 0.0             # rad/s
    r_noise: float = 0.0            # rad/s
    r_resolution: float = 0.0       # rad/s
    position_noise: float = 0.0     # m, each of north and east
    seed: int = 0
    k: int = 0                      # the draws' step
    w: tuple = field(init=False)    # this step's four standard normal draws

    def __post_init__(self) -> None:
        require_finite(**{n: getattr(self, n) for n in (
            "psi_bias", "psi_noise", "psi_resolution", "r_bias", "r_noise", "r_resolution",
            "position_noise")})
        for name in ("psi_noise", "psi_resolution", "r_noise", "r_resolution",
                     "position_noise"):
            if getattr(self, name) < 0.0:
                raise ValueError(f"parameter {name} must be >= 0, got {getattr(self, name)}")
        self._draw()

    def _draw(self) -> None:
        self.w = tuple(float(w) for w in
                       np.random.default_rng([self.seed, self.k]).standard_normal(4))

    def heading(self, psi: float) -> float:
        return quantised(psi + self.psi_bias + self.psi_noise * self.w[0], self.psi_resolution)

    def rate(self, r: float) -> float:
        return quantised(r + self.r_bias + self.r_noise * self.w[1], self.r_resolution)

    def position(self, x: float, y: float) -> tuple[float, float]:
        return x + self.position_noise * self.w[2], y + self.position_noise * self.w[3]

    def step(self) -> None:
        """The next step's draws."""
        self.k += 1
        self._draw()

    def snapshot(self) -> dict:
        return {"k": self.k}

    def restore(self, snapshot: dict) -> None:
        self.k = int(snapshot["k"])
        self._draw()
