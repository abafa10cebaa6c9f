"""Wave loads from the modified Pierson-Moskowitz spectrum, eqs (14)-(17): omega_i uniform in
N equal-variance bins of 98 % of it (equal spacing repeats the sea), theta_i = omega_i t - k_i xi
+ phi_i, xi the travel along the waves (a vessel state: the encounter phase, exactly). A seed
gives the same bits on every CPU: exactly rounded operations, decimal logarithms, no BLAS."""
from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, localcontext
from functools import lru_cache

import numpy as np

from .data import G, RHO_WATER, Hull

BAND = 0.98                     # the share of the spectrum's variance the components hold


def spectrum(omega: np.ndarray | float, Hs: float, T0: float) -> np.ndarray | float:
    """S(omega) = A omega^-5 exp(-B omega^-4), m^2 s, eq (17), A = Hs^2 B / 4."""
    B = _spectrum_b(T0)
    return Hs * Hs / 4.0 * B / omega ** 5 * np.exp(-B / omega ** 4)


def _spectrum_b(T0: float) -> float:
    """B = 16 pi^3 / (0.710 T0)^4 by products: ``**`` is libm's pow, whose last bit varies."""
    Tz = 0.710 * T0
    return 16.0 * math.pi * math.pi * math.pi / (Tz * Tz * Tz * Tz)


@lru_cache(maxsize=64)
def _bins(T0: float, n: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Variance fractions F and frequencies omega = (B / -ln F)^(1/4) (rad/s, decimal) of
    the edges of N equal-variance bins of the spectrum's central BAND."""
    tail = 0.5 * (1.0 - BAND)
    fractions = np.linspace(tail, 1.0 - tail, n + 1).tolist()
    B = Decimal(_spectrum_b(T0))
    with localcontext() as context:
        context.prec = 34
        edges = tuple(float((B / -Decimal(f).ln()).sqrt().sqrt()) for f in fractions)
    return tuple(fractions), edges


@dataclass(frozen=True)
class WaveComponents:
    """N regular components of one sea-state realisation."""
    omega: np.ndarray       # rad/s
    k: np.ndarray           # rad/m
    amplitude: np.ndarray   # m
    phase: np.ndarray       # rad

    @classmethod
    def from_spectrum(cls, Hs: float, T0: float, n: int, seed: int) -> WaveComponents:
        edges_fraction, edges = map(np.array, _bins(T0, n))
        rng = np.random.default_rng(seed)
        omega = rng.uniform(edges[:-1], edges[1:])
        phase = rng.uniform(0.0, 2.0 * math.pi, n)
        m0_bins = Hs * Hs / 16.0 * np.diff(edges_fraction)
        return cls(omega=omega, k=omega * omega / G,
                   amplitude=np.sqrt(2.0 * m0_bins), phase=phase)


class WaveLoads:
    """Eqs (14)-(16) on a block hull, s_i = A_i k_i sin(theta_i), beta = psi_w - psi:
    X_w, Y_w = rho g B L T (cos, sin)(beta) sum s_i, N_w = rho g B L (L^2 - B^2) / 24
    sin(2 beta) sum s_i^2; summed in order (no matrix product), into arrays made once."""

    def __init__(self, components: WaveComponents, h: Hull, psi_w: float):
        n, rho = len(components.omega), RHO_WATER
        self.components = components
        self.psi_w = psi_w
        self._c_force = rho * G * h.B * h.L * h.T
        self._c_moment = rho * G * h.B * h.L * (h.L * h.L - h.B * h.B) / 24.0
        self._slope_amplitude = components.amplitude * components.k
        self._omega_t, self._s, self._s2 = np.empty(n), np.empty(n), np.empty(n)
        self._t: float | None = None                  # the time of _omega_t
        self._key: tuple = (None, None, None)         # the last evaluation's arguments,
        self._loads = (0.0, 0.0, 0.0)                 # and its loads

    def __call__(self, t: float, xi: float, psi: float) -> tuple[float, float, float]:
        if self._key == (t, xi, psi):
            return self._loads
        if t != self._t:
            np.multiply(self.components.omega, t, self._omega_t)
            self._t = t
        s = np.multiply(self.components.k, xi, self._s)    # theta_i, in place
        np.subtract(self._omega_t, s, s)
        np.add(s, self.components.phase, s)
        np.sin(s, s)
        np.multiply(self._slope_amplitude, s, s)          # s_i = A_i k_i sin(theta_i)
        beta = self.psi_w - psi
        # np.add.reduce: s.sum() without its wrapper; not np.dot, whose BLAS bits vary
        force = self._c_force * float(np.add.reduce(s))
        sum_s2 = float(np.add.reduce(np.multiply(s, s, self._s2)))
        self._key = (t, xi, psi)
        self._loads = (force * math.cos(beta), force * math.sin(beta),
                       self._c_moment * math.sin(2.0 * beta) * sum_s2)
        return self._loads
