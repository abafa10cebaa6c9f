"""The vessel of ``ship_fmu.vessel`` for M members at once: ``Vessel.step`` on arrays.

Each state is an (M,) array, the wave components (M, N) arrays; every member keeps its own
parameters, sea and steering gear. The hull's Coriolis and damping forces, the
kinematics, the actuators' forces and the RK4 update are the scalar model's own functions,
which take arrays as they take floats; what the scalar model writes with branches (the
steering gear's kink, the step cut there) or with scalar calls (the wave loads) is written
here on arrays, operation for operation in the scalar model's order, and pinned to it bit
for bit by tests/test_ensemble.py.
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from ship_fmu.hull import coriolis_forces, damping_forces, kinematics
from ship_fmu.thrusters import actuator_model
from ship_fmu.vessel import Vessel, axpy, rk4_update

from . import exact

Arrays = tuple[np.ndarray, ...]


class RudderArrays:
    """``ship_fmu.steering_gear.RudderMotion`` of every member: the rudder angle a time s
    into the step, with delta_c held (s an array or a float)."""

    def __init__(self, delta0: np.ndarray, delta_c: np.ndarray, delta_max: np.ndarray,
                 delta_rate_max: np.ndarray):
        self.delta0 = delta0
        self.target = np.minimum(np.maximum(delta_c, -delta_max), delta_max)
        error = self.target - delta0
        self.velocity = np.copysign(delta_rate_max, error)
        self.reach = np.abs(error) / delta_rate_max

    def __call__(self, s: np.ndarray | float) -> np.ndarray:
        return np.where(s >= self.reach, self.target, self.delta0 + self.velocity * s)


class WaveArrays:
    """``ship_fmu.waves.WaveLoads`` of every member: (X_w, Y_w, N_w) from (M, N) components,
    eqs (14)-(16), each sum over a member's N components in numpy's order for N values."""

    def __init__(self, vessels: Sequence[Vessel]):
        loads = [v.waves for v in vessels]
        self.omega = np.array([w.components.omega for w in loads])
        self.k = np.array([w.components.k for w in loads])
        self.phase = np.array([w.components.phase for w in loads])
        self.slope_amplitude = np.array([w._slope_amplitude for w in loads])
        self.psi_w = np.array([w.psi_w for w in loads])
        self.c_force = np.array([w._c_force for w in loads])
        self.c_moment = np.array([w._c_moment for w in loads])

    def __call__(self, t: np.ndarray | float, xi: np.ndarray, psi: np.ndarray) -> Arrays:
        omega_t = self.omega * (t[:, None] if isinstance(t, np.ndarray) else t)
        s = np.subtract(omega_t, self.k * xi[:, None], omega_t)
        np.add(s, self.phase, s)
        np.sin(s, s)
        np.multiply(self.slope_amplitude, s, s)               # s_i = A_i k_i sin(theta_i)
        beta = self.psi_w - psi
        force = self.c_force * np.add.reduce(s, axis=1)
        sum_s2 = np.add.reduce(np.multiply(s, s, s), axis=1)
        return (force * np.cos(beta), force * np.sin(beta),
                self.c_moment * np.sin(2.0 * beta) * sum_s2)


def _calm(t: np.ndarray | float, xi: np.ndarray, psi: np.ndarray) -> Arrays:
    return (0.0, 0.0, 0.0)


class VesselArrays:
    """M vessels, stepped together with their inputs held; built from the scalar vessels
    as the in-process route initialised them (their parameters, sea and initial state)."""

    STATES = ("x", "y", "psi", "u", "v", "r", "xi")

    def __init__(self, vessels: Sequence[Vessel], h: float):
        first = vessels[0]
        self.hull = first.hull
        for vessel in vessels:
            if vessel.hull != self.hull or vessel.actuators != first.actuators:
                raise ValueError("the members' vessels differ in hull or actuators")
            if vessel._cut_of(h)[0] != 1:
                raise ValueError(f"a member's h_max = {vessel.params.h_max} s cuts the "
                                 f"{h} s step")
        self.actuators = first.actuators
        self.m11_inv = first._m11_inv
        self.minv = first._minv
        self.delta_max = np.array([v.params.delta_max for v in vessels])
        self.delta_rate_max = np.array([v.params.delta_rate_max for v in vessels])
        waves = [v.waves is not None for v in vessels]
        if any(waves) and not all(waves):
            raise ValueError("the members mix calm water and waves")
        self.waves = WaveArrays(vessels) if all(waves) else None
        self.wave_loads = self.waves if self.waves is not None else _calm
        self.psi_w = self.waves.psi_w if self.waves is not None else None
        for name in self.STATES:
            setattr(self, name, np.array([getattr(v, name) for v in vessels]))
        self.delta = np.array([v.delta for v in vessels])
        self._shaft_speeds: tuple = ()
        self._forces: list[tuple[np.ndarray | None, Callable]] = []

    def set_shaft_speeds(self, n1: np.ndarray, n2: np.ndarray, n3: np.ndarray) -> None:
        """The actuators' forces as a function of the rudder angle, for each distinct set
        of shaft speeds among the members (``thrusters.actuator_model``, on arrays)."""
        speeds = np.stack([n1, n2, n3], axis=1)
        distinct = np.unique(speeds, axis=0)
        self._forces = [(None if len(distinct) == 1 else np.all(speeds == row, axis=1),
                         actuator_model(self.actuators, *map(float, row))) for row in distinct]

    def forces(self, delta: np.ndarray) -> Arrays:
        """tau_th of every member at rudder angles ``delta``."""
        if len(self._forces) == 1:
            return self._forces[0][1](delta)
        out = [np.empty_like(delta) for _ in range(3)]
        for members, forces in self._forces:
            for total, part in zip(out, forces(delta[members])):
                total[members] = part
        return tuple(out)

    def rates(self, t: np.ndarray | float, state: Arrays, tau_th: Arrays) -> Arrays:
        """``Vessel.rates`` of every member."""
        _, _, psi, u, v, r, xi = state
        cX, cY, cN = coriolis_forces(self.hull, u, v, r)
        dX, dY, dN = damping_forces(self.hull, u, v, r)
        tX, tY, tN = tau_th
        wX, wY, wN = self.wave_loads(t, xi, psi)
        fX = tX + wX - cX - dX
        fY = tY + wY - cY - dY
        fN = tN + wN - cN - dN
        i22, i23, i32, i33 = self.minv
        x_dot, y_dot, psi_dot = kinematics(psi, u, v, r, np.cos, np.sin)
        xi_dot = (exact.hypot(u, v) * np.cos(self.psi_w - psi) if self.waves is not None
                  else 0.0)                      # calm water: no load depends on xi
        return (x_dot, y_dot, psi_dot, fX * self.m11_inv,
                i22 * fY + i23 * fN, i32 * fY + i33 * fN, xi_dot)

    def step(self, t: float, h: float, delta_c: np.ndarray) -> None:
        """``Vessel.step`` of every member from t to t + h: one RK4 step, or two where the
        rudder reaches its command or its stop within the step."""
        gear = RudderArrays(self.delta, delta_c, self.delta_max, self.delta_rate_max)
        y = tuple(getattr(self, name) for name in self.STATES)
        split = (0.0 < gear.reach) & (gear.reach < h)
        whole = self._rk4(t, 0.0, np.where(split, gear.reach, h), y, gear)
        if split.any():
            rest = self._rk4(t, gear.reach, h - gear.reach, whole, gear)
            whole = tuple(np.where(split, b, a) for a, b in zip(whole, rest))
        for name, value in zip(self.STATES, whole):
            setattr(self, name, value)
        self.delta = gear(h)

    def _rk4(self, t: float, start: np.ndarray | float, length: np.ndarray, y: Arrays,
             gear: RudderArrays) -> Arrays:
        """``Vessel._integrate`` over one RK4 step of ``length`` from t + start."""
        hs = length
        hh, c = 0.5 * hs, hs / 6.0
        s = start + 0.0 * hs
        ts = t + s
        delta0, delta1, delta2 = gear(s), gear(s + hh), gear(s + hs)
        tau0 = self.forces(delta0)
        tau1 = tau0 if np.array_equal(delta1, delta0) else self.forces(delta1)
        tau2 = tau1 if np.array_equal(delta2, delta1) else self.forces(delta2)
        k1 = self.rates(ts, y, tau0)
        k2 = self.rates(ts + hh, axpy(hh, k1, y), tau1)
        k3 = self.rates(ts + hh, axpy(hh, k2, y), tau1)
        k4 = self.rates(ts + hs, axpy(hs, k3, y), tau2)
        return rk4_update(c, y, k1, k2, k3, k4)

