"""CyberShip II model data, which the paper cites but does not print: hull from Skjetne,
Smogeli and Fossen (2004); propellers and rudders from Sveen (2003), as MSS ``initCS2.m``;
lever arms from Skjetne (2004). Fossen's signs: X_u < 0 is damping."""
from dataclasses import dataclass

G = 9.81                        # m/s^2
RHO_WATER = 1000.0              # kg/m^3, the fresh water of the model basin (MCLab)
RHO_AIR = 1.224                 # kg/m^3, at 20 C (Fossen 2011, sec. 8.1)
SCALE = 70.0                    # length ratio of CyberShip II to the supply ship it models


@dataclass(frozen=True)
class Hull:
    """Rigid-body, added-mass and damping coefficients of eqs (4)-(6)."""
    m: float = 23.8          # kg
    I_z: float = 1.76        # kg m^2
    x_g: float = 0.046       # m
    L: float = 1.255         # m, length overall
    B: float = 0.29          # m, breadth
    T: float = 0.05          # m, mean draught
    # added mass
    X_udot: float = -2.0
    Y_vdot: float = -10.0
    Y_rdot: float = 0.0
    N_vdot: float = 0.0
    N_rdot: float = -1.0
    # surge damping: X_u u + X_|u|u |u| u + X_uuu u^3
    X_u: float = -0.72253
    X_uu: float = -1.32742
    X_uuu: float = -5.86643
    # sway damping
    Y_v: float = -0.88965
    Y_vv: float = -36.47287   # Y_|v|v
    Y_rv: float = -0.805      # Y_|r|v
    Y_r: float = -7.250
    Y_vr: float = -0.845      # Y_|v|r
    Y_rr: float = -3.450      # Y_|r|r
    # yaw damping
    N_v: float = 0.03130
    N_vv: float = 3.95645     # N_|v|v
    N_rv: float = 0.130       # N_|r|v
    N_r: float = -1.900
    N_vr: float = 0.080       # N_|v|r
    N_rr: float = -0.750      # N_|r|r


@dataclass(frozen=True)
class Actuators:
    """Propeller, bow-thruster and rudder constants of eqs (8)-(13), n in rev/s."""
    k_Tp: float = 3.74e-3     # main propellers 1, 2, n >= 0
    k_Tn: float = 5.05e-3     # main propellers 1, 2, n < 0
    k_T3p: float = 1.84e-4    # bow thruster, n >= 0
    k_T3n: float = 1.88e-4    # bow thruster, n < 0
    k_Ld1: float = 0.927      # rudder lift, per rad
    k_Ld2: float = -0.557     # rudder lift, per rad^2
    k_Ln: float = 2.1e-2      # rudder lift, per rev/s
    k_Dd1: float = 0.079      # rudder drag, per rad
    k_Dd2: float = 0.615      # rudder drag, per rad^2
    k_Dn: float = 9.64e-3     # rudder drag, per rev/s
    l_yT: float = 0.078       # |l_yT1| = |l_yT2|, m
    l_xT3: float = 0.466      # |l_xT3|, m
    l_xR: float = 0.549       # |l_xR1| = |l_xR2|, m
