"""Wave loads from the modified Pierson-Moskowitz spectrum, eqs (14)-(17).

The sea is a sum of N regular components. Component i has frequency omega_i,
wave number k_i = omega_i^2 / g (deep water), amplitude A_i and a random phase
phi_i; its slope at the ship is s_i = A_i k_i sin(theta_i), and its elevation
A_i sin(theta_i).

Discretisation: the band [omega_lo, omega_hi] holds ``band_fraction`` (98 %) of
the spectrum's variance, with equal tails. It is cut into N bins of equal variance
(the spectrum's cumulative distribution has a closed form, so the bin edges are
exact quantiles, computed in decimal arithmetic and rounded once: see
``frequency_at_fraction``); A_i = sqrt(2 m0_i) with m0_i the exact variance of bin i, so the
components carry the band's variance exactly. omega_i is drawn uniformly inside
its bin: equally spaced frequencies would repeat the sea every 2 pi / d_omega
(about 15 s here). Frequencies and phases come from a seeded generator, so a seed
names one realisation, with the same bits on every CPU: the realisation uses
only exactly rounded operations (+, -, *, /, sqrt, and decimal logarithms), never
a vectorised transcendental function or BLAS, whose last bits vary with the CPU.

Encounter phase: theta_i must obey d theta_i/dt = omega_e,i = omega_i - k_i U cos(beta),
with U the ship's speed and beta = psi_w - psi. Writing omega_e,i * t instead drifts
without bound as soon as U or psi change. All N phase equations share one
unknown, the ship's travel along the wave direction xi, d xi/dt = U cos(beta), so

    theta_i(t) = omega_i t - k_i xi(t) + phi_i

solves every one of them exactly. The vessel integrates xi as a state; t is the
communication point the master gives, so neither accumulates rounding.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, localcontext
from functools import lru_cache

import numpy as np

from .data import G, RHO_WATER, Hull


def spectrum(omega: np.ndarray | float, Hs: float, T0: float) -> np.ndarray | float:
    """Modified Pierson-Moskowitz spectral density S(omega), m^2 s, eq (17).

    S = A omega^-5 exp(-B omega^-4) with B = 16 pi^3 / (0.710 T0)^4 and A = Hs^2 B / 4.
    """
    B = _spectrum_b(T0)
    return Hs * Hs / 4.0 * B / omega ** 5 * np.exp(-B / omega ** 4)


def _spectrum_b(T0: float) -> float:
    """B in S = A omega^-5 exp(-B omega^-4); the variance below omega is m0 exp(-B/omega^4).

    Products, not ``**``: Python's float power is the C library's pow, whose last bit
    depends on the CPU.
    """
    Tz = 0.710 * T0
    return 16.0 * math.pi * math.pi * math.pi / (Tz * Tz * Tz * Tz)


def variance_fraction_below(omega: np.ndarray | float, T0: float) -> np.ndarray | float:
    """Share of the spectrum's variance m0 = Hs^2/16 at frequencies below omega."""
    return np.exp(-_spectrum_b(T0) / np.asarray(omega, dtype=float) ** 4)


def frequency_at_fraction(fraction: float, T0: float) -> float:
    """Inverse of ``variance_fraction_below``: omega = (B / -ln F)^(1/4), rad/s.

    In decimal arithmetic at 34 digits (its ln and sqrt are correctly rounded) and
    rounded once to a float, so the result is the same on every CPU and C library,
    where numpy's vectorised log and power round differently from one CPU to another.
    """
    with localcontext() as context:
        context.prec = 34
        quotient = Decimal(_spectrum_b(T0)) / -Decimal(fraction).ln()
        return float(quotient.sqrt().sqrt())


@lru_cache(maxsize=64)
def _bins(T0: float, n: int, band_fraction: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The n + 1 bin edges of the band, as variance fractions and as frequencies (rad/s):
    the same for every seed, and slow to compute in decimal, so computed once."""
    tail = 0.5 * (1.0 - band_fraction)
    fractions = np.linspace(tail, 1.0 - tail, n + 1).tolist()
    return tuple(fractions), tuple(frequency_at_fraction(f, T0) for f in fractions)


@dataclass(frozen=True)
class WaveComponents:
    """N regular components of one sea-state realisation."""

    omega: np.ndarray       # rad/s
    k: np.ndarray           # rad/m
    amplitude: np.ndarray   # m
    phase: np.ndarray       # rad

    @classmethod
    def from_spectrum(cls, Hs: float, T0: float, n: int, seed: int,
                      band_fraction: float = 0.98) -> WaveComponents:
        """Equal-variance discretisation of eq (17); see the module docstring."""
        edges_fraction, edges = map(np.array, _bins(T0, n, band_fraction))
        rng = np.random.default_rng(seed)
        omega = rng.uniform(edges[:-1], edges[1:])
        phase = rng.uniform(0.0, 2.0 * math.pi, n)
        m0_bins = Hs * Hs / 16.0 * np.diff(edges_fraction)
        return cls(omega=omega, k=omega * omega / G,
                   amplitude=np.sqrt(2.0 * m0_bins), phase=phase)

    def phases(self, t: float, xi: float, out: np.ndarray | None = None,
               omega_t: np.ndarray | None = None) -> np.ndarray:
        """theta_i(t) = omega_i t - k_i xi + phi_i (into ``out``, if given).

        ``omega_t``: omega_i t already computed for this t, to be used, not recomputed.
        """
        if omega_t is None:
            omega_t = self.omega * t
        out = np.multiply(self.k, xi, out)
        np.subtract(omega_t, out, out)
        return np.add(out, self.phase, out)


class WaveLoads:
    """First-order wave forces on a block-shaped hull, eqs (14)-(16).

    With s_i = A_i k_i sin(theta_i) and beta = psi_w - psi:
    X_w = rho g B L T cos(beta) sum s_i, Y_w = rho g B L T sin(beta) sum s_i and
    N_w = rho g B L (L^2 - B^2) / 24 sin(2 beta) sum s_i^2.

    On 50 components numpy's cost is its calls, not its arithmetic, so an
    evaluation makes no call it can share: omega_i t is computed once per time
    (RK4's second and third stages share one), into arrays allocated once, and the
    last evaluation is kept (the end of a step is usually the next one's first
    stage). The arithmetic of every value is the one the equations write, in their
    order, so the results are those of a plain evaluation to the bit. (Summing both
    sums in one matrix product, or the phases in one, would save a call or three but
    add in another order, and the chattering sliding-mode loop turns last bits into
    visibly different runs.)
    """

    def __init__(self, components: WaveComponents, hull: Hull, psi_w: float,
                 rho: float = RHO_WATER):
        h, n = hull, len(components.omega)
        self.components = components
        self.psi_w = psi_w
        self._c_force = rho * G * h.B * h.L * h.T
        self._c_moment = rho * G * h.B * h.L * (h.L * h.L - h.B * h.B) / 24.0
        self._slope_amplitude = components.amplitude * components.k
        # Work arrays, so that an evaluation allocates nothing.
        self._omega_t, self._s, self._s2 = np.empty(n), np.empty(n), np.empty(n)
        self._t: float | None = None                  # the time of _omega_t
        self._key: tuple = (None, None, None)         # the last evaluation's arguments,
        self._loads = (0.0, 0.0, 0.0)                 # and its loads

    def __call__(self, t: float, xi: float, psi: float) -> tuple[float, float, float]:
        """(X_w, Y_w, N_w) at time t, travel xi and heading psi."""
        if self._key == (t, xi, psi):
            return self._loads
        if t != self._t:
            np.multiply(self.components.omega, t, self._omega_t)
            self._t = t
        s = self.components.phases(t, xi, self._s, self._omega_t)
        np.sin(s, s)
        np.multiply(self._slope_amplitude, s, s)          # s_i = A_i k_i sin(theta_i)
        beta = self.psi_w - psi
        # np.add.reduce: what s.sum() computes, without its wrapper; and sum s_i^2 the
        # same way, not by np.dot, whose BLAS kernel (hence its last bit) varies by CPU
        force = self._c_force * float(np.add.reduce(s))
        sum_s2 = float(np.add.reduce(np.multiply(s, s, self._s2)))
        self._key = (t, xi, psi)
        self._loads = (force * math.cos(beta), force * math.sin(beta),
                       self._c_moment * math.sin(2.0 * beta) * sum_s2)
        return self._loads
