"""Wind loads on the hull above water (Fossen 2011, sec. 8.1.1): Blendermann's (1994)
coefficients for an offshore supply vessel (his Table 2, Fossen's Table 8.2), on the
projected areas of CyberShip II's full-scale supply ship, estimated from its 88 m x 20 m hull
(not published), Froude-scaled to 1:70: model-scale wind on model-scale areas gives the
full-scale loads / 70^3."""
import math

from .data import RHO_AIR, SCALE

CD_T, CD_L_BOW, CD_L_STERN, DELTA_B = 0.90, 0.55, 0.80, 0.55    # Blendermann, supply vessel
A_F = 260.0 / SCALE**2          # m^2, frontal projected area above water (20 m x 13 m)
A_L = 700.0 / SCALE**2          # m^2, lateral (88 m x 8 m)
S_L = 9.0 / SCALE               # m, its centroid ahead of midships (the forward superstructure)
L_OA = 1.255                    # m


def wind_loads(u: float, v: float, psi: float, wind: tuple[float, float]
               ) -> tuple[float, float, float]:
    """(X, Y, N) of the wind, whose velocity is ``wind`` (north, east, m/s), on a ship at
    heading psi moving at (u, v) over ground; gamma is the relative wind's angle off the
    bow, positive from port (eqs 8.22-8.30, N odd in gamma as the hull is symmetric)."""
    c, s = math.cos(psi), math.sin(psi)
    u_r = u - (c * wind[0] + s * wind[1])            # the air's velocity past the ship
    v_r = v - (-s * wind[0] + c * wind[1])
    gamma = -math.atan2(v_r, u_r)
    q = 0.5 * RHO_AIR * (u_r * u_r + v_r * v_r)      # dynamic pressure
    cd_l = CD_L_BOW if abs(gamma) <= 0.5 * math.pi else CD_L_STERN
    sin_2 = math.sin(2.0 * gamma)
    den = 1.0 - 0.5 * DELTA_B * (1.0 - cd_l * A_F / (A_L * CD_T)) * sin_2 * sin_2
    C_X = -cd_l * math.cos(gamma) / den
    C_Y = CD_T * math.sin(gamma) / den
    C_N = (S_L / L_OA - 0.18 * (abs(gamma) - 0.5 * math.pi)) * C_Y
    return q * C_X * A_F, q * C_Y * A_L, q * C_N * A_L * L_OA
