"""Linear design models of the sliding-mode autopilot, eqs (22)-(32), (45)-(46): eq (45) as
printed (its n_22 and b_1 do not follow from the hull data: ../shared/cybership2.md, erratum
4), or the Jacobian of our ship model at nu = [u0, 0, 0]."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ship_fmu.data import Actuators, Hull
from ship_fmu.hull import coriolis_forces, damping_forces, mass_matrix
from ship_fmu.thrusters import actuator_model
from ship_fmu.vessel import N_PROPELLER


@dataclass(frozen=True)
class SwayYawModel:
    """M nu_dot + N nu = b delta with nu = [v, r], eq (23)."""
    M: np.ndarray
    N: np.ndarray
    b: np.ndarray


PAPER_EQ45 = SwayYawModel(
    M=np.array([[33.8000, 1.0948], [1.0948, 2.7600]]),
    N=np.array([[0.8897, 14.9900], [2.3687, 2.9948]]),
    b=np.array([0.4304, -0.2363]),
)


def _derivative(f: Callable[[float], np.ndarray], step: float = 1e-3) -> np.ndarray:
    """df/dx at 0: central differences with one Richardson step (exact for the |a| b terms)."""
    def central(h: float) -> np.ndarray:
        return (f(h) - f(-h)) / (2.0 * h)
    return 2.0 * central(step / 2.0) - central(step)


def linearised_ship(u0: float) -> SwayYawModel:
    """Sway-yaw model of the ship linearised at surge speed u0, eqs (23)-(25)."""
    hull = Hull()

    def hydrodynamic(v: float, r: float) -> np.ndarray:
        return np.add(coriolis_forces(hull, u0, v, r), damping_forces(hull, u0, v, r))[1:]
    N = np.column_stack([_derivative(lambda v: hydrodynamic(v, 0.0)),
                         _derivative(lambda r: hydrodynamic(0.0, r))])
    forces = actuator_model(Actuators(), N_PROPELLER, N_PROPELLER, 0.0)
    return SwayYawModel(M=mass_matrix(hull)[1:, 1:], N=N,
                        b=_derivative(lambda d: np.array(forces(d)[1:])))


@dataclass(frozen=True)
class NomotoModel:
    """psi/delta = K / (s (1 + T s)), eqs (26)-(34), as the state model (33)."""
    T: float        # T1 + T2 - T3, s
    a22: float      # -1/T (the paper writes a_11 after eq (34); it is a_22)
    b2: float       # K / T, K = -K_R (31)

    @classmethod
    def from_sway_yaw(cls, model: SwayYawModel) -> NomotoModel:
        (m11, m12), (m21, m22) = model.M
        (n11, n12), (n21, n22) = model.N
        b1, b2 = model.b
        det_N = n11 * n22 - n12 * n21
        T1_plus_T2 = (n11 * m22 + n22 * m11 - n12 * m21 - n21 * m12) / det_N   # (28)
        K_R = float((n21 * b1 - n11 * b2) / det_N)                              # (29)
        T3 = (m21 * b1 - m11 * b2) / det_N / K_R                                # (30)
        T = float(T1_plus_T2 - T3)
        return cls(T=T, a22=-1.0 / T, b2=-K_R / T)


def design_model(name: str, u0: float) -> SwayYawModel:
    """The sway-yaw model the parameter ``design_model`` names: 'paper' or 'ship'."""
    if name == "paper":
        return PAPER_EQ45
    if name == "ship":
        if not u0 > 0.0:
            raise ValueError(f"parameter u0 must be > 0 for design_model 'ship', got {u0}")
        return linearised_ship(u0)
    raise ValueError(f"parameter design_model must be 'paper' (eq 45 as printed) or 'ship' "
                     f"(our model linearised at u0), got {name!r}")
