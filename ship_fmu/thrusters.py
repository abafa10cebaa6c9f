"""Propellers, bow thruster and rudders: tau_th = T u, eqs (8)-(13), n in rev/s, delta in rad.
T's first two rows, which the paper prints as zeros, are Sveen's (2003) and Skjetne's (2004);
a positive rudder (n > 0) gives r < 0, psi decreasing, as eqs (20), (45) agree."""
from typing import Callable

from .data import Actuators


def thrust(n: float, k_p: float, k_n: float) -> float:
    """Nominal thrust of a propeller at zero rudder, eq (8)."""
    return k_p * n * n if n >= 0.0 else k_n * abs(n) * n


def actuator_model(act: Actuators, n1: float, n2: float,
                   n3: float) -> Callable[[float], tuple[float, float, float]]:
    """tau_th of the rudder angle at fixed shaft speeds, eqs (8)-(13); a propeller turning
    astern (n_i < 0) gives its rudder no lift or drag."""
    T1 = thrust(n1, act.k_Tp, act.k_Tn)
    T2 = thrust(n2, act.k_Tp, act.k_Tn)
    T3 = thrust(n3, act.k_T3p, act.k_T3n)
    lift1, drag1 = (T1 * (1.0 + act.k_Ln * n1), T1 * (1.0 + act.k_Dn * n1)) if n1 >= 0.0 \
        else (0.0, 0.0)
    lift2, drag2 = (T2 * (1.0 + act.k_Ln * n2), T2 * (1.0 + act.k_Dn * n2)) if n2 >= 0.0 \
        else (0.0, 0.0)
    k_Ld1, k_Ld2, k_Dd1, k_Dd2 = act.k_Ld1, act.k_Ld2, act.k_Dd1, act.k_Dd2
    l_yT, l_xT3, l_xR = act.l_yT, act.l_xT3, act.l_xR

    def forces(delta: float) -> tuple[float, float, float]:
        a = abs(delta)
        lift = k_Ld1 + k_Ld2 * a                 # eq (9):  L_i = lift_i (k_Ld1 + k_Ld2 |d|) d
        drag = k_Dd1 * a + k_Dd2 * a * a         # eq (10): D_i = drag_i (k_Dd1 |d| + k_Dd2 d^2)
        L1, L2 = lift1 * lift * delta, lift2 * lift * delta
        F1, F2 = T1 - drag1 * drag, T2 - drag2 * drag
        return (F1 + F2,                                             # eqs (11)-(13)
                T3 + L1 + L2,
                l_yT * (F1 - F2) + l_xT3 * T3 - l_xR * (L1 + L2))
    return forces
