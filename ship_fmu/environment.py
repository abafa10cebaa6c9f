"""What moves the water and the air around the ship: an ocean current whose speed and
direction are first-order Gauss-Markov processes about their means (Fossen 2011, sec. 8.3),
stepped exactly (the process's own decay and spread over each step), its draws seeded per
step so that a saved and restored state goes on as it would have; and a mean wind with gusts
from the NORSOK N-003 spectrum (ISO 19901-1), a sum of seeded harmonics in time."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from decimal import Decimal, localcontext

import numpy as np

from fmukit.numerics import require_finite

from .data import SCALE

F_BAND = (Decimal("0.0005"), Decimal("0.5"))    # Hz at full scale: the gusts' frequencies
_ROOT_SCALE = Decimal(SCALE).sqrt()


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


@dataclass
class Wind:
    """A wind of mean speed V_mean (m/s at model scale) blowing towards beta, with gusts along
    it from the NORSOK spectrum S(f) = 320 (U/10)^2 / (1 + x^n)^(5/3n), x = 172 f (U/10)^-3/4,
    n = 0.468 (U the full-scale mean at 10 m, m/s; f Hz), in ``components`` geometric bands
    Froude-scaled to 1:70; the spectrum in decimal arithmetic, the same bits on any CPU."""
    V_mean: float = 0.0
    beta: float = 0.0
    components: int = 0         # 0: a steady wind
    seed: int = 0
    gusts: tuple = field(init=False, repr=False)    # (omega rad/s, amplitude m/s, phase rad)

    def __post_init__(self) -> None:
        require_finite(V_mean=self.V_mean, beta=self.beta)
        if self.V_mean < 0.0:
            raise ValueError(f"parameter V_w_mean must be >= 0, got {self.V_mean}")
        n, U = self.components, Decimal(self.V_mean) * _ROOT_SCALE / 10
        phases = np.random.default_rng(self.seed).uniform(0.0, 2.0 * math.pi, n).tolist()
        with localcontext() as context:
            context.prec = 34
            low, high = F_BAND
            edges = [low * (high / low) ** (Decimal(i) / n) for i in range(n + 1)] \
                if U and n else []
            self.gusts = tuple((*_band(a, b, U), phase)
                               for a, b, phase in zip(edges, edges[1:], phases))

    def speed(self, t: float) -> float:
        """The wind speed at time t (s, model scale), >= 0."""
        gust = 0.0
        for omega, amplitude, phase in self.gusts:
            gust += amplitude * math.cos(omega * t + phase)
        return max(0.0, self.V_mean + gust)


@dataclass
class Environment:
    """The current and the wind at time t: the environment FMU's model."""
    current: Current
    wind: Wind
    t: float = 0.0

    def step(self, t: float, h: float) -> None:
        self.current.step(h)
        self.t = t + h

    def snapshot(self) -> dict:
        return {**self.current.snapshot(), "t": self.t}

    def restore(self, snapshot: dict) -> None:
        self.current.restore(snapshot)
        self.t = float(snapshot["t"])


def _band(a: Decimal, b: Decimal, U: Decimal) -> tuple[float, float]:
    """(omega rad/s, amplitude m/s) at model scale of the gusts between a and b Hz at full
    scale, U the full-scale mean / 10 m/s: the spectrum at the band's geometric middle."""
    f, n = (a * b).sqrt(), Decimal("0.468")
    S = 320 * U * U / (1 + (172 * f / U ** Decimal("0.75")) ** n) ** (5 / (3 * n))
    return float(2 * Decimal(math.pi) * f * _ROOT_SCALE), float((2 * S * (b - a)).sqrt()
                                                                  / _ROOT_SCALE)
