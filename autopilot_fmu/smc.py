"""Sliding-mode autopilot, eqs (35)-(44), designed on the Nomoto model (33) by pole placement
(38), h the eigenvector of A_c^T of the smaller eigenvalue, N from (40)-(41). Eq (39) is read
to stabilise: as printed it feeds the heading back with the wrong sign (docs/fmus.md)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from fmukit.numerics import substeps, wrap

from .design import NomotoModel, SwayYawModel

H_MAX = 0.1                     # s, the largest RK4 step of the reference model


def reference_step_bound(omega_n: float, zeta: float) -> float:
    """The largest RK4 step of model (44), s: |lambda| h <= 1 on its fastest eigenvalue."""
    fastest = omega_n * (zeta + math.sqrt(max(zeta * zeta - 1.0, 0.0)))
    return H_MAX if fastest * H_MAX <= 1.0 else 1.0 / fastest


def reference_acceleration(psi_d: float, psi_z: float, r_z: float, omega_n: float,
                           zeta: float, wrap: Callable = wrap) -> float:
    """r_z_dot of eq (44); floats, or arrays with an array ``wrap`` (``cosim.ensemble``)."""
    return omega_n * omega_n * wrap(psi_d - psi_z) - 2.0 * zeta * omega_n * r_z


def reference_rk4(psi_d: float, psi_z: float, r_z: float, hs: float, omega_n: float,
                  zeta: float, wrap: Callable = wrap) -> tuple[float, float]:
    """(psi_z, r_z) after one RK4 step of hs of the reference model (44), psi_d held."""
    a1, b1 = r_z, reference_acceleration(psi_d, psi_z, r_z, omega_n, zeta, wrap)
    a2 = r_z + 0.5 * hs * b1
    b2 = reference_acceleration(psi_d, psi_z + 0.5 * hs * a1, a2, omega_n, zeta, wrap)
    a3 = r_z + 0.5 * hs * b2
    b3 = reference_acceleration(psi_d, psi_z + 0.5 * hs * a2, a3, omega_n, zeta, wrap)
    a4 = r_z + hs * b3
    b4 = reference_acceleration(psi_d, psi_z + hs * a3, a4, omega_n, zeta, wrap)
    return (psi_z + hs / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
            r_z + hs / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4))


@dataclass(frozen=True)
class SlidingModeDesign:
    """Gains of the sliding-mode autopilot for a Nomoto model, eqs (38)-(41)."""
    nomoto: NomotoModel
    K: tuple[float, float]
    h: tuple[float, float]

    @classmethod
    def from_model(cls, model: SwayYawModel, lambda1: float = -0.0005,
                   lambda2: float = -7.8128) -> SlidingModeDesign:
        for name, value in (("lambda1", lambda1), ("lambda2", lambda2)):
            if not value < 0.0:                       # the FMU's ranges refuse the rest
                raise ValueError(f"parameter {name} must be a closed-loop eigenvalue < 0, "
                                 f"got {value}")
        nomoto = NomotoModel.from_sway_yaw(model)
        b2, a22 = nomoto.b2, nomoto.a22
        # Pole placement, eq (38), on the state model (33), A = [[0, 1], [0, a22]], B = [0, b2]:
        # det(sI - A_c) = s^2 - (a22 - b2 k2) s + b2 k1, A_c = A - B K^T.
        k1 = lambda1 * lambda2 / b2
        k2 = (a22 - lambda1 - lambda2) / b2
        A_c_T = [[0.0, 0.0 - b2 * k1], [1.0, a22 - b2 * k2]]
        slow = min(_eigenvalues(A_c_T), key=abs)
        h1, h2 = _null_vector(A_c_T, slow)
        scale = math.copysign(1.0, h1) / math.hypot(h1, h2)
        # Eqs (40)-(41): [N_x; N_u] = [[A, B], [C, D]]^-1 [0; 1] = [1, 0; 0] with C = [1, 0]
        # and D = 0, so N = N_u + K^T N_x = k1: u_eq (39) = k1 (psi_z - psi) - k2 r.
        return cls(nomoto=nomoto, K=(k1, k2), h=(h1 * scale, h2 * scale))


# The design's linear algebra written out in exactly rounded operations, not by LAPACK,
# whose last bits vary by CPU: the chattering loop turns a last bit into another run.
def _eigenvalues(M: list[list[float]]) -> tuple[float, float]:
    trace, det = M[0][0] + M[1][1], M[0][0] * M[1][1] - M[0][1] * M[1][0]
    discriminant = trace * trace - 4.0 * det
    if discriminant < 0.0:
        raise ValueError(f"the closed loop has complex eigenvalues (trace {trace}, "
                         f"determinant {det}); lambda1 and lambda2 must be real")
    q = 0.5 * (trace + math.copysign(math.sqrt(discriminant), trace))
    return (q, det / q) if q != 0.0 else (0.0, trace)


def _null_vector(M: list[list[float]], eigenvalue: float) -> tuple[float, float]:
    """h with (M - eigenvalue I) h = 0, from the row of larger norm."""
    rows = [(M[0][0] - eigenvalue, M[0][1]), (M[1][0], M[1][1] - eigenvalue)]
    a, b = max(rows, key=lambda row: math.hypot(*row))
    return -b, a


class SlidingModeAutopilot:
    """Reference model (44) as state, control law (37)-(43) as output."""

    def __init__(self, design: SlidingModeDesign, eta_h: float = 10.0, phi_h: float = 0.3,
                 omega_n: float = 0.1, zeta: float = 0.85, psi_z: float = 0.0,
                 r_z: float = 0.0, equivalent_control: str = "paper"):
        for name, value in (("phi_h", phi_h), ("omega_n", omega_n), ("zeta", zeta)):
            if not value > 0.0:                       # the FMU's ranges refuse the rest
                raise ValueError(f"parameter {name} must be > 0, got {value}")
        if equivalent_control not in ("paper", "tracking"):
            raise ValueError(f"parameter equivalent_control must be 'paper' (eq 39) or "
                             f"'tracking' (-K^T (x - x_z)), got {equivalent_control!r}")
        self.design = design
        self.tracking = equivalent_control == "tracking"
        self.eta_h, self.phi_h, self.omega_n, self.zeta = eta_h, phi_h, omega_n, zeta
        self.psi_z, self.r_z = psi_z, r_z
        self._h_max = reference_step_bound(omega_n, zeta)

    def r_z_dot(self, psi_d: float, psi_z: float, r_z: float) -> float:
        """Eq (44) at the reference state (psi_z, r_z)."""
        return reference_acceleration(psi_d, psi_z, r_z, self.omega_n, self.zeta)

    def sigma(self, psi: float, r: float) -> float:
        """Sliding surface sigma_h, eq (37)."""
        h1, h2 = self.design.h
        return h1 * wrap(self.psi_z - psi) + h2 * (self.r_z - r)

    def command(self, psi: float, r: float, psi_d: float) -> float:
        """delta_c = u_eq + u_sw, eq (43), rad: u_eq (39), or -K^T (x - x_z) if 'tracking';
        u_sw = h^T [r_z, r_z_dot] - eta_h tanh(sigma_h / phi_h) (42)."""
        (k1, k2), (h1, h2) = self.design.K, self.design.h
        u_eq = k1 * wrap(self.psi_z - psi) + k2 * ((self.r_z if self.tracking else 0.0) - r)
        u_sw = (h1 * self.r_z + h2 * self.r_z_dot(psi_d, self.psi_z, self.r_z)
                - self.eta_h * math.tanh(self.sigma(psi, r) / self.phi_h))
        return u_eq + u_sw

    def step(self, t: float, h: float, psi_d: float) -> None:
        n = substeps(h, self._h_max, "of the reference model")
        for _ in range(n):
            self.psi_z, self.r_z = reference_rk4(psi_d, self.psi_z, self.r_z, h / n,
                                                 self.omega_n, self.zeta)

    def snapshot(self) -> dict[str, float]:
        return {"psi_z": self.psi_z, "r_z": self.r_z}

    def restore(self, snapshot: dict[str, float]) -> None:
        self.psi_z, self.r_z = float(snapshot["psi_z"]), float(snapshot["r_z"])
