"""What moves the water around the ship (Fossen 2011, sec. 8.3): an ocean current whose speed
and direction are first-order Gauss-Markov processes about their means, stepped exactly (the
process's own decay and spread over each step), its draws seeded per step so that a saved and
restored state goes on as it would have."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fmukit.numerics import require_finite


@dataclass
class Current:
    V_mean: float = 0.0         # m/s, the mean speed
    beta_mean: float = 0.0      # rad, the mean direction it flows towards, from north
    T_c: float = 100.0          # s, correlation time (1 / mu of Fossen's eq 8.2)
    sigma_V: float = 0.0        # m/s, the speed's standard deviation about its mean
    sigma_beta: float = 0.0     # rad, the direction's
    seed: int = 0
    V: float = math.nan         # m/s, now (starts at the mean)
    beta: float = math.nan      # rad, now
    k: int = 0                  # steps taken: the next draw's key

    def __post_init__(self) -> None:
        require_finite(V_mean=self.V_mean, beta_mean=self.beta_mean, T_c=self.T_c,
                       sigma_V=self.sigma_V, sigma_beta=self.sigma_beta)
        for name in ("V_mean", "sigma_V", "sigma_beta"):
            if getattr(self, name) < 0.0:
                raise ValueError(f"parameter {name} must be >= 0, got {getattr(self, name)}")
        if self.T_c <= 0.0:
            raise ValueError(f"parameter T_c must be > 0, got {self.T_c}")
        self.V = self.V_mean if math.isnan(self.V) else self.V
        self.beta = self.beta_mean if math.isnan(self.beta) else self.beta

    def step(self, h: float) -> None:
        """h s on: x -> mean + (x - mean) a + sigma sqrt(1 - a^2) w, a = exp(-h / T_c)."""
        a = math.exp(-h / self.T_c)
        spread = math.sqrt(1.0 - a * a)
        w_V, w_beta = (float(w) for w in
                       np.random.default_rng([self.seed, self.k]).standard_normal(2))
        self.V = max(0.0, self.V_mean + (self.V - self.V_mean) * a + self.sigma_V * spread * w_V)
        self.beta = self.beta_mean + (self.beta - self.beta_mean) * a + \
            self.sigma_beta * spread * w_beta
        self.k += 1

    def snapshot(self) -> dict:
        return {"V": self.V, "beta": self.beta, "k": self.k}

    def restore(self, snapshot: dict) -> None:
        self.V, self.beta, self.k = float(snapshot["V"]), float(snapshot["beta"]), \
            int(snapshot["k"])
