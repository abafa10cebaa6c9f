"""Propellers, bow thruster and rudders: tau_th = T u, eqs (8)-(13).

Shaft speeds n are in rev/s, rudder angles in rad. Both rudders sit in the
slipstream of their propeller and take the same angle delta.

The paper prints the first two rows of the actuator matrix T, eq (13), as zeros.
The real matrix (Sveen 2003; Skjetne 2004) puts T_i - D_i of the main propellers
into surge, the bow thruster and both rudder lifts into sway, and keeps the printed
yaw row::

        [ 1      1     0      0      0    ]
    T = [ 0      0     1      1      1    ]
        [ l_yT  -l_yT  l_xT3 -l_xR  -l_xR ]

Which way a positive rudder turns the ship: with n > 0, a positive delta gives a
positive lift L_i (eq 9, since k_Ld1 + k_Ld2 |delta| > 0 up to 95 deg), i.e. a
force to starboard at the stern and a negative yaw moment -l_xR (L_1 + L_2). The
ship turns to port: **positive rudder -> r < 0, psi decreasing**. The linear model
of eq (45) agrees (b_1 > 0, b_2 < 0), and so does the PD law of eq (20), which
commands a negative rudder to increase the heading.
"""
from __future__ import annotations

from .data import Actuators


def thrust(n: float, k_p: float, k_n: float) -> float:
    """Nominal thrust of a propeller at zero rudder, eq (8)."""
    return k_p * n * n if n >= 0.0 else k_n * abs(n) * n


def rudder_lift(act: Actuators, T: float, n: float, delta: float) -> float:
    """Rudder lift in the slipstream of a propeller with thrust T, eq (9)."""
    if n < 0.0:
        return 0.0
    return T * (1.0 + act.k_Ln * n) * (act.k_Ld1 + act.k_Ld2 * abs(delta)) * delta


def rudder_drag(act: Actuators, T: float, n: float, delta: float) -> float:
    """Rudder drag in the slipstream of a propeller with thrust T, eq (10)."""
    if n < 0.0:
        return 0.0
    a = abs(delta)
    return T * (1.0 + act.k_Dn * n) * (act.k_Dd1 * a + act.k_Dd2 * a * a)


def actuator_forces(act: Actuators, n1: float, n2: float, n3: float,
                    delta: float) -> tuple[float, float, float]:
    """tau_th = T u for both rudders at angle delta, eqs (11)-(13)."""
    T1 = thrust(n1, act.k_Tp, act.k_Tn)
    T2 = thrust(n2, act.k_Tp, act.k_Tn)
    T3 = thrust(n3, act.k_T3p, act.k_T3n)
    L1 = rudder_lift(act, T1, n1, delta)
    L2 = rudder_lift(act, T2, n2, delta)
    F1 = T1 - rudder_drag(act, T1, n1, delta)
    F2 = T2 - rudder_drag(act, T2, n2, delta)
    return (
        F1 + F2,
        T3 + L1 + L2,
        act.l_yT * (F1 - F2) + act.l_xT3 * T3 - act.l_xR * (L1 + L2),
    )
