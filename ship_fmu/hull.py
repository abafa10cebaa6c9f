"""The 3-DOF manoeuvring model, eqs (1)-(6): eta_dot = R(psi) nu (1)-(2), M nu_dot + C(nu) nu
+ D(nu) nu = tau (3), eta = [x, y, psi] (north, east, heading), nu = [u, v, r]."""
import math
from typing import Callable

import numpy as np

from .data import Hull

Vector3 = tuple[float, float, float]


def kinematics(psi: float, u: float, v: float, r: float,
               cos: Callable = math.cos, sin: Callable = math.sin) -> Vector3:
    """eta_dot = R(psi) nu, eqs (1)-(2); numpy's cos and sin for arrays of states."""
    c, s = cos(psi), sin(psi)
    return u * c - v * s, u * s + v * c, r


def mass_matrix(h: Hull) -> np.ndarray:
    """System inertia matrix M = M_RB + M_A, eq (4)."""
    return np.array([
        [h.m - h.X_udot, 0.0, 0.0],
        [0.0, h.m - h.Y_vdot, h.m * h.x_g - h.Y_rdot],
        [0.0, h.m * h.x_g - h.N_vdot, h.I_z - h.N_rdot],
    ])


def coriolis_forces(h: Hull, u: float, v: float, r: float) -> Vector3:
    """C(nu) nu with C = C_RB + C_A, eq (5)."""
    c_rb13 = -h.m * (h.x_g * r + v)
    c_rb23 = h.m * u
    c13 = h.Y_vdot * v + 0.5 * (h.N_vdot + h.Y_rdot) * r     # C_A(1, 3)
    c23 = h.X_udot * u                                     # C_A(2, 3) = -c23
    return (
        (c_rb13 + c13) * r,
        (c_rb23 - c23) * r,
        -(c_rb13 + c13) * u - (c_rb23 - c23) * v,
    )


def damping_forces(h: Hull, u: float, v: float, r: float) -> Vector3:
    """D(nu) nu with D = D_L + D_NL(nu), eq (6); d_32 uses N_|r|v, as Skjetne et al.
    (2004); the paper prints Y_|r|v there."""
    au, av, ar = abs(u), abs(v), abs(r)
    d11 = -(h.X_u + h.X_uu * au + h.X_uuu * u * u)
    d22 = -(h.Y_v + h.Y_vv * av + h.Y_rv * ar)
    d23 = -(h.Y_r + h.Y_vr * av + h.Y_rr * ar)
    d32 = -(h.N_v + h.N_vv * av + h.N_rv * ar)
    d33 = -(h.N_r + h.N_vr * av + h.N_rr * ar)
    return d11 * u, d22 * v + d23 * r, d32 * v + d33 * r
