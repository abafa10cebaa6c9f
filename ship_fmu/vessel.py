"""The vessel: CyberShip II hull, actuators, steering gear and waves, by RK4 with the inputs
held, in equal sub-steps <= h_max, cut where the rudder reaches its command or stop (RK4 keeps
its order only on smooth pieces, ``cosim.accuracy``). psi is not wrapped."""
import math
from dataclasses import dataclass
from typing import Callable

from fmukit.numerics import require_finite, substeps

from .data import G, Actuators, Hull
from .hull import coriolis_forces, damping_forces, kinematics, mass_matrix
from .steering_gear import DELTA_MAX, DELTA_RATE_MAX, RudderMotion
from .thrusters import actuator_model
from .waves import WaveComponents, WaveLoads
from .wind import wind_loads

State = tuple[float, float, float, float, float, float, float]   # (x, y, psi, u, v, r, xi)
MAX_STEEPNESS = 7.0             # waves break beyond Hs / lambda_p = 1/7
N_PROPELLER = 8.13              # rev/s, the paper's main propellers: 0.3 m/s in calm water


@dataclass(frozen=True)
class VesselParameters:
    """Initial state, steering gear and sea state; names as in the FMU."""
    x0: float = 0.0
    y0: float = 0.0
    psi0: float = 0.0
    u0: float = 0.3
    v0: float = 0.0
    r0: float = 0.0
    delta_max: float = DELTA_MAX
    delta_rate_max: float = DELTA_RATE_MAX
    Hs: float = 0.0             # m, 0 = calm water
    T0: float = 0.8             # s, modal period
    psi_w: float = math.pi      # rad, wave direction
    wave_seed: int = 0
    wave_components: int = 50
    h_max: float = 0.1          # s, largest RK4 step

    def __post_init__(self) -> None:     # what the FMU's declared ranges do not refuse
        if not self.delta_max > 0.0:
            raise ValueError(f"parameter delta_max must be > 0, got {self.delta_max}")
        if not self.delta_rate_max >= 0.0:      # 0: the gear has failed, the rudder stays
            raise ValueError(f"parameter delta_rate_max must be >= 0, got "
                             f"{self.delta_rate_max}")
        # steeper waves break (Stokes' limit): the block model's loads would diverge
        peak_wavelength = G * self.T0 * self.T0 / (2.0 * math.pi)
        if self.Hs > peak_wavelength / MAX_STEEPNESS:
            raise ValueError(f"parameter Hs = {self.Hs} m with T0 = {self.T0} s: steepness "
                             f"Hs / lambda_p = {self.Hs / peak_wavelength:.3g} exceeds 1/"
                             f"{MAX_STEEPNESS:g}, steeper than waves can be")


class Vessel:
    """CyberShip II in calm water or waves, stepped with inputs held."""
    STATE = ("x", "y", "psi", "u", "v", "r", "delta", "xi", "t")

    def __init__(self, params: VesselParameters = VesselParameters()):
        self.params, self.hull, self.actuators = params, Hull(), Actuators()
        M = mass_matrix(self.hull).tolist()
        det = M[1][1] * M[2][2] - M[1][2] * M[2][1]
        self._m11_inv = 1.0 / M[0][0]
        self._minv = (M[2][2] / det, -M[1][2] / det, -M[2][1] / det, M[1][1] / det)
        self.waves, self._wave_loads = None, calm_water
        self._shafts, self._forces = None, None        # the last shaft speeds, their tau_th
        self._current: tuple[float, float] | None = None   # (north, east) m/s, held a step
        self._wind: tuple[float, float] | None = None      # the same, relative to the water
        if params.Hs > 0.0:
            components = WaveComponents.from_spectrum(
                params.Hs, params.T0, params.wave_components, params.wave_seed)
            self.waves = self._wave_loads = WaveLoads(components, self.hull, params.psi_w)
        self.x, self.y, self.psi = params.x0, params.y0, params.psi0
        self.u, self.v, self.r = params.u0, params.v0, params.r0
        self.delta = self.xi = self.t = 0.0
        self.X_w, self.Y_w, self.N_w = self._wave_loads(self.t, self.xi, self.psi)

    def rates(self, t: float, state: State, tau_th: tuple[float, float, float]) -> State:
        """d/dt of the state, eqs (1)-(17), under actuator forces tau_th."""
        return state_rates(self.hull, self._minv, self._m11_inv, self._wave_loads,
                           self.params.psi_w, t, state, tau_th, current=self._current,
                           wind=self._wind)

    def step(self, t: float, h: float, delta_c: float,
             n1: float = N_PROPELLER, n2: float = N_PROPELLER, n3: float = 0.0,
             V_c: float = 0.0, beta_c: float = 0.0, V_w: float = 0.0,
             beta_w: float = 0.0) -> None:
        """A step of h s with the inputs held: the rudder command, the shaft speeds, the
        ocean current, V_c m/s flowing towards beta_c rad from north (none if V_c = 0), and
        the wind, V_w m/s blowing towards beta_w (none if V_w = 0)."""
        require_finite(delta_c=delta_c, n1=n1, n2=n2, n3=n3, V_c=V_c, beta_c=beta_c, V_w=V_w,
                       beta_w=beta_w)
        self._current = c = (V_c * math.cos(beta_c), V_c * math.sin(beta_c)) if V_c else None
        self._wind = (V_w * math.cos(beta_w) - (c[0] if c else 0.0),
                      V_w * math.sin(beta_w) - (c[1] if c else 0.0)) if V_w else None
        if (n1, n2, n3) != self._shafts:
            self._shafts, self._forces = (n1, n2, n3), actuator_model(self.actuators, n1, n2, n3)
        forces = self._forces
        gear = RudderMotion(self.delta, delta_c, self.params.delta_max,
                            self.params.delta_rate_max)
        y = (self.x, self.y, self.psi, self.u, self.v, self.r, self.xi)
        ends = (gear.reach, h) if 0.0 < gear.reach < h else (h,)   # a piece either side of
        for start, end in zip((0.0, *ends), ends):                   # the rudder's kink
            n_sub, hs = self._cut_of(end - start)
            for j in range(n_sub):
                y = rk4_step(self.rates, forces, gear, t, start + j * hs, hs, y)
        self.x, self.y, self.psi, self.u, self.v, self.r, self.xi = y
        self.delta = gear(h)
        self.t = t + h
        self.X_w, self.Y_w, self.N_w = self._wave_loads(self.t, self.xi, self.psi)

    def _cut_of(self, length: float) -> tuple[int, float]:
        """(number, length) of the equal RK4 sub-steps <= h_max that cut ``length``."""
        n_sub = substeps(length, self.params.h_max, f"of at most h_max = {self.params.h_max} s")
        return n_sub, length / n_sub

    def snapshot(self) -> dict[str, float]:
        return {name: getattr(self, name) for name in self.STATE}

    def restore(self, snapshot: dict[str, float]) -> None:
        for name in self.STATE:
            setattr(self, name, float(snapshot[name]))
        self.X_w, self.Y_w, self.N_w = self._wave_loads(self.t, self.xi, self.psi)


def state_rates(hull: Hull, minv: tuple[float, float, float, float], m11_inv: float,
                wave_loads: Callable, psi_w: float, t: float, state: State,
                tau_th: tuple[float, float, float], hypot: Callable = math.hypot,
                cos: Callable = math.cos, sin: Callable = math.sin,
                current: tuple[float, float] | None = None,
                wind: tuple[float, float] | None = None) -> State:
    """d/dt of the state, eqs (1)-(17); floats, or arrays with numpy's cos, sin and an
    exact hypot (``cosim.ensemble``). In an ocean current (north, east, m/s; irrotational,
    held over the step) u and v are relative to the water, in the hull's forces as in calm
    water, and the current carries the ship (Fossen 2011, sec. 10.3: eta_dot = R(psi) nu_r
    + v_c). ``wind``: the wind's velocity relative to the water, whose loads add (floats)."""
    _, _, psi, u, v, r, xi = state
    cX, cY, cN = coriolis_forces(hull, u, v, r)
    dX, dY, dN = damping_forces(hull, u, v, r)
    tX, tY, tN = tau_th
    wX, wY, wN = wave_loads(t, xi, psi)
    fX = tX + wX - cX - dX
    fY = tY + wY - cY - dY
    fN = tN + wN - cN - dN
    if wind is not None:
        aX, aY, aN = wind_loads(u, v, psi, wind)
        fX, fY, fN = fX + aX, fY + aY, fN + aN
    i22, i23, i32, i33 = minv
    x_dot, y_dot, psi_dot = kinematics(psi, u, v, r, cos, sin)
    if current is not None:
        x_dot, y_dot = x_dot + current[0], y_dot + current[1]
    xi_dot = hypot(u, v) * cos(psi_w - psi)
    return (x_dot, y_dot, psi_dot, fX * m11_inv,
            i22 * fY + i23 * fN, i32 * fY + i33 * fN, xi_dot)


def calm_water(t: float, xi: float, psi: float) -> tuple[float, float, float]:
    return (0.0, 0.0, 0.0)


def _at_rest(delta: float, before: float) -> bool:
    """The rudder has not moved: its forces stand (not at 0, whose sign they keep)."""
    return delta == before != 0.0


def rk4_step(rates: Callable, forces: Callable, gear: Callable, t: float, s: float, hs: float,
             y: State, same: Callable = _at_rest) -> State:
    """One RK4 step of hs from t + s, the rudder's forces at s, s + hs/2 and s + hs; floats,
    or arrays with an array ``same`` (``cosim.ensemble``)."""
    hh = 0.5 * hs
    delta0, delta1, delta2 = gear(s), gear(s + hh), gear(s + hs)
    tau0 = forces(delta0)
    tau1 = tau0 if same(delta1, delta0) else forces(delta1)
    tau2 = tau1 if same(delta2, delta1) else forces(delta2)
    ts = t + s
    k1 = rates(ts, y, tau0)
    k2 = rates(ts + hh, axpy(hh, k1, y), tau1)
    k3 = rates(ts + hh, axpy(hh, k2, y), tau1)
    k4 = rates(ts + hs, axpy(hs, k3, y), tau2)
    return rk4_update(hs / 6.0, y, k1, k2, k3, k4)


def axpy(a: float, x: State, y: State) -> State:
    """y + a x for the 7 states, written out: it runs three times a step."""
    return (y[0] + a * x[0], y[1] + a * x[1], y[2] + a * x[2], y[3] + a * x[3],
            y[4] + a * x[4], y[5] + a * x[5], y[6] + a * x[6])


def rk4_update(c: float, y: State, k1: State, k2: State, k3: State, k4: State) -> State:
    """The RK4 update y + h/6 (k1 + 2 k2 + 2 k3 + k4), with c = h/6."""
    return (y[0] + c * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            y[1] + c * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
            y[2] + c * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]),
            y[3] + c * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3]),
            y[4] + c * (k1[4] + 2.0 * k2[4] + 2.0 * k3[4] + k4[4]),
            y[5] + c * (k1[5] + 2.0 * k2[5] + 2.0 * k3[5] + k4[5]),
            y[6] + c * (k1[6] + 2.0 * k2[6] + 2.0 * k3[6] + k4[6]))
