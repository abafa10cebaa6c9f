"""Heading observer with wave filtering: Fossen's passive observer (Fossen and Strand 1999;
Fossen 2011, sec. 11.4) on the compass alone. The measured heading is taken as low-frequency
heading + the output of a wave filter h(s) = s / (s^2 + 2 lambda omega_0 s + omega_0^2); the
low-frequency part follows a first-order model r_dot = (K delta - r) / T + b, whose bias b
takes what it leaves out: the sway it couples to and slow disturbances (wind, current). The
autopilot steers on psi_hat and r_hat, with the wave-frequency yaw filtered out, so the rudder
does not chase the waves."""
from __future__ import annotations

import math
from dataclasses import dataclass

from fmukit.numerics import require_finite, substeps, wrap

H_MAX = 0.005               # s, RK4 step: omega_c h stays well inside its stability region
# T and K from the yaw row of our ship's sway-yaw model at 0.3 m/s (autopilot_fmu.design,
# M nu_dot + N nu = b delta): r_dot = -(M^-1 N)_rr r + (M^-1 b)_r delta. Nomoto's first-order
# fit (T = -8.6 s: the ship is course-unstable) has 1/17 of the rudder's direct yaw
# acceleration, and an observer on it destabilises the PD's fast rate loop (Kd = 50 s).
NOMOTO_T, NOMOTO_K = 1.5632162460096055, -0.1789835763018252
State = tuple[float, float, float, float, float]          # xi_1, xi_2, psi, r, b


@dataclass
class HeadingObserver:
    omega_0: float = 2.0 * math.pi / 0.8    # rad/s, the wave filter's peak (the sea's T0)
    lam: float = 0.1                        # the wave filter's relative damping
    zeta_n: float = 1.0                     # the notch's relative damping, > lam
    omega_c: float = 1.1 * 2.0 * math.pi / 0.8  # rad/s, the filter cut-off, > omega_0
    omega_lf: float = 1.5                   # rad/s, the low-frequency estimates' bandwidth
    T: float = NOMOTO_T                     # s, the yaw model's time constant
    K: float = NOMOTO_K                     # the yaw model's gain, rad/s per rad
    x: State = (0.0, 0.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        require_finite(**{n: getattr(self, n) for n in ("omega_0", "lam", "zeta_n", "omega_c",
                                                         "omega_lf", "T", "K")})
        for rule, holds in (("omega_0 > 0", self.omega_0 > 0.0), ("T != 0", self.T != 0.0),
                            ("0 <= lam < zeta_n", 0.0 <= self.lam < self.zeta_n),
                            ("omega_c > omega_0", self.omega_c > self.omega_0),
                            ("0 < omega_lf < (omega_c + 1/T) / 3",
                             0.0 < 3.0 * self.omega_lf < self.omega_c + 1.0 / self.T)):
            if not holds:
                raise ValueError(f"the observer's parameters must keep {rule}")
        # the wave filter's notch (Fossen 2011, eq 11.126), and K2 = omega_c; K3, K4 place the
        # low-frequency error's poles at -p and a double one at -omega_lf
        a, w = -1.0 / self.T, self.omega_lf
        p = self.omega_c - a - 2.0 * w
        self.gains = (-2.0 * (self.zeta_n - self.lam) * self.omega_c / self.omega_0,
                      2.0 * self.omega_0 * (self.zeta_n - self.lam), self.omega_c,
                      p * w * w, a * self.omega_c + 2.0 * w * p + w * w)

    def start(self, psi_m: float) -> None:
        """The estimates start at the first reading, at rest."""
        self.x = (0.0, 0.0, psi_m, 0.0, 0.0)

    def rates(self, x: State, psi_m: float, delta: float) -> State:
        xi_1, xi_2, psi, r, b = x
        k11, k12, k2, k3, k4 = self.gains
        y = wrap(psi_m - psi - xi_2)                       # the innovation
        w0 = self.omega_0
        return (xi_2 + k11 * y, -w0 * w0 * xi_1 - 2.0 * self.lam * w0 * xi_2 + k12 * y,
                r + k2 * y, (self.K * delta - r) / self.T + b + k4 * y, k3 * y)

    def step(self, h: float, psi_m: float, delta: float) -> None:
        """h s on, the compass reading psi_m and the rudder delta held (RK4)."""
        require_finite(psi_m=psi_m, delta=delta)
        n = substeps(h, H_MAX, f"of at most {H_MAX} s (the observer's)")
        hs, x = h / n, self.x
        for _ in range(n):
            k1 = self.rates(x, psi_m, delta)
            k2 = self.rates(tuple(a + 0.5 * hs * d for a, d in zip(x, k1)), psi_m, delta)
            k3 = self.rates(tuple(a + 0.5 * hs * d for a, d in zip(x, k2)), psi_m, delta)
            k4 = self.rates(tuple(a + hs * d for a, d in zip(x, k3)), psi_m, delta)
            x = tuple(a + hs / 6.0 * (d1 + 2.0 * d2 + 2.0 * d3 + d4)
                      for a, d1, d2, d3, d4 in zip(x, k1, k2, k3, k4))
        self.x = x

    @property
    def psi_hat(self) -> float:
        return self.x[2]

    @property
    def r_hat(self) -> float:
        return self.x[3]

    def snapshot(self) -> dict:
        return {"x": list(self.x)}

    def restore(self, snapshot: dict) -> None:
        self.x = tuple(float(v) for v in snapshot["x"])
