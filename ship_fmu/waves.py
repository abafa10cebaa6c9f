"""Wave loads from the modified Pierson-Moskowitz spectrum, eqs (14)-(17).

The sea is a sum of N regular components. Component i has frequency omega_i,
wave number k_i = omega_i^2 / g (deep water), amplitude A_i and a random phase
phi_i; its slope at the ship is s_i = A_i k_i sin(theta_i), and its elevation
A_i sin(theta_i).

Discretisation: the band [omega_lo, omega_hi] holds ``band_fraction`` (98 %) of
the spectrum's variance, with equal tails. It is cut into N bins of equal variance
(the spectrum's cumulative distribution has a closed form, so the bin edges are
exact quantiles); A_i = sqrt(2 m0_i) with m0_i the exact variance of bin i, so the
components carry the band's variance exactly. omega_i is drawn uniformly inside
its bin: equally spaced frequencies would repeat the sea every 2 pi / d_omega
(about 15 s here). Frequencies and phases come from a seeded generator, so a seed
names one realisation.

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

import numpy as np

from .data import G, RHO_WATER, Hull


def spectrum(omega: np.ndarray | float, Hs: float, T0: float) -> np.ndarray | float:
    """Modified Pierson-Moskowitz spectral density S(omega), m^2 s, eq (17)."""
    Tz4 = (0.710 * T0) ** 4
    return (4.0 * math.pi ** 3 * Hs ** 2 / (Tz4 * omega ** 5)
            * np.exp(-16.0 * math.pi ** 3 / (Tz4 * omega ** 4)))


def _spectrum_b(T0: float) -> float:
    """B in S = A omega^-5 exp(-B omega^-4); the variance below omega is m0 exp(-B/omega^4)."""
    return 16.0 * math.pi ** 3 / (0.710 * T0) ** 4


def variance_fraction_below(omega: np.ndarray | float, T0: float) -> np.ndarray | float:
    """Share of the spectrum's variance m0 = Hs^2/16 at frequencies below omega."""
    return np.exp(-_spectrum_b(T0) / np.asarray(omega, dtype=float) ** 4)


def frequency_at_fraction(fraction: np.ndarray | float, T0: float) -> np.ndarray | float:
    """Inverse of ``variance_fraction_below``."""
    return (_spectrum_b(T0) / -np.log(fraction)) ** 0.25


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
        tail = 0.5 * (1.0 - band_fraction)
        edges_fraction = np.linspace(tail, 1.0 - tail, n + 1)
        edges = frequency_at_fraction(edges_fraction, T0)
        rng = np.random.default_rng(seed)
        omega = rng.uniform(edges[:-1], edges[1:])
        phase = rng.uniform(0.0, 2.0 * math.pi, n)
        m0_bins = Hs ** 2 / 16.0 * np.diff(edges_fraction)
        return cls(omega=omega, k=omega ** 2 / G,
                   amplitude=np.sqrt(2.0 * m0_bins), phase=phase)

    def phases(self, t: float, xi: float, out: np.ndarray | None = None,
               work: np.ndarray | None = None) -> np.ndarray:
        """theta_i(t) = omega_i t - k_i xi + phi_i (into ``out``, with ``work``, if given)."""
        out = np.multiply(self.omega, t, out=out)
        np.subtract(out, np.multiply(self.k, xi, out=work), out=out)
        return np.add(out, self.phase, out=out)

    def elevation(self, t: float, xi: float) -> float:
        """Wave elevation at the ship, m."""
        return float(self.amplitude @ np.sin(self.phases(t, xi)))


class WaveLoads:
    """First-order wave forces on a block-shaped hull, eqs (14)-(16)."""

    def __init__(self, components: WaveComponents, hull: Hull, psi_w: float,
                 rho: float = RHO_WATER):
        h = hull
        self.components = components
        self.psi_w = psi_w
        self._slope_amplitude = components.amplitude * components.k
        self._c_force = rho * G * h.B * h.L * h.T
        self._c_moment = rho * G * h.B * h.L * (h.L ** 2 - h.B ** 2) / 24.0
        self._s = np.empty_like(components.omega)       # work arrays: no allocation per call
        self._kxi = np.empty_like(components.omega)
        self._last: tuple = (None, None)

    def __call__(self, t: float, xi: float, psi: float) -> tuple[float, float, float]:
        """(X_w, Y_w, N_w) at time t, travel xi and heading psi.

        The last result is kept: the loads at the end of a step are those of the
        next step's first RK4 stage.
        """
        key, loads = self._last
        if key == (t, xi, psi):
            return loads
        s = self.components.phases(t, xi, out=self._s, work=self._kxi)
        np.sin(s, out=s)
        np.multiply(self._slope_amplitude, s, out=s)    # s_i = A_i k_i sin(theta_i)
        beta = self.psi_w - psi
        sum_s = float(s.sum())
        force = self._c_force * sum_s
        loads = (force * math.cos(beta),
                 force * math.sin(beta),
                 self._c_moment * math.sin(2.0 * beta) * float(s @ s))
        self._last = ((t, xi, psi), loads)
        return loads
