"""``Vessel.step`` for M members, states (M,) and wave components (M, N): the scalar model's
functions on arrays, its branches rewritten op for op."""
from __future__ import annotations

from operator import attrgetter
from typing import Sequence

import numpy as np

from ship_fmu.thrusters import actuator_model
from ship_fmu.vessel import Vessel, calm_water, rk4_step, state_rates

from . import exact
from .control import columns

Arrays = tuple[np.ndarray, ...]


class RudderArrays:
    """``ship_fmu.steering_gear.RudderMotion`` of every member (s an array or a float)."""

    def __init__(self, delta0: np.ndarray, delta_c: np.ndarray, delta_max: np.ndarray,
                 delta_rate_max: np.ndarray):
        self.delta0 = delta0
        self.target = np.minimum(np.maximum(delta_c, -delta_max), delta_max)
        error = self.target - delta0
        self.velocity = np.copysign(delta_rate_max, error)
        self.reach = np.divide(np.abs(error), delta_rate_max, out=np.full_like(error, np.inf),
                               where=delta_rate_max != 0.0)       # 0: the gear has failed

    def __call__(self, s: np.ndarray | float) -> np.ndarray:
        return np.where(s >= self.reach, self.target, self.delta0 + self.velocity * s)


class WaveArrays:
    """``ship_fmu.waves.WaveLoads`` of every member, eqs (14)-(16)."""
    SOURCES = {"omega": "components.omega", "k": "components.k", "phase": "components.phase",
               "slope_amplitude": "_slope_amplitude", "psi_w": "psi_w", "c_force": "_c_force",
               "c_moment": "_c_moment"}

    def __init__(self, vessels: Sequence[Vessel]):
        for name, source in self.SOURCES.items():
            setattr(self, name, np.array([attrgetter(source)(v.waves) for v in vessels]))
        self._work = (np.empty_like(self.omega), np.empty_like(self.omega))
        self._part = {name: np.empty_like(getattr(self, name)) for name in self.SOURCES}

    def take(self, lanes: np.ndarray) -> WaveArrays:
        """The members ``lanes`` only, in spare arrays valid until the next ``take``."""
        part = object.__new__(WaveArrays)
        for name in self.SOURCES:
            setattr(part, name, np.take(getattr(self, name), lanes, axis=0,
                                        out=self._part[name][:len(lanes)]))
        part._work, part._part = self._work, None
        return part

    def __call__(self, t: np.ndarray | float, xi: np.ndarray, psi: np.ndarray) -> Arrays:
        # into arrays made once: made afresh, each would be an mmap where glibc's mmap
        # threshold is fixed, as Dask's workers fix it
        m = len(xi)
        s, ks = self._work[0][:m], self._work[1][:m]
        np.multiply(self.omega, t[:, None] if isinstance(t, np.ndarray) else t, s)
        np.subtract(s, np.multiply(self.k, xi[:, None], ks), s)
        np.add(s, self.phase, s)
        np.sin(s, s)
        np.multiply(self.slope_amplitude, s, s)               # s_i = A_i k_i sin(theta_i)
        beta = self.psi_w - psi
        force = self.c_force * np.add.reduce(s, axis=1)
        sum_s2 = np.add.reduce(np.multiply(s, s, s), axis=1)
        return (force * np.cos(beta), force * np.sin(beta),
                self.c_moment * np.sin(2.0 * beta) * sum_s2)


def _no_travel(u: np.ndarray, v: np.ndarray) -> float:
    """Calm water: no load depends on xi, its rate stays 0 (saves ``hypot``)."""
    return 0.0


class VesselArrays:
    """M vessels stepped together, built from initialised vessels of one sea (calm, or N wave
    components), none cutting a step, and their shafts (n1, n2, n3)."""
    STATES = ("x", "y", "psi", "u", "v", "r", "xi")

    def __init__(self, vessels: Sequence[Vessel], shafts: tuple[float, float, float]):
        self.vessel = vessels[0]                            # the hull and mass matrix of all
        self.forces = actuator_model(self.vessel.actuators, *shafts)
        self.waves = None if self.vessel.waves is None else WaveArrays(vessels)
        columns(self, [v.params for v in vessels], ("psi_w", "delta_max", "delta_rate_max"))
        columns(self, vessels, (*self.STATES, "delta"))

    def put(self, lanes: np.ndarray, vessels: Sequence[Vessel]) -> None:
        """Lanes ``lanes`` become the initialised ``vessels`` (of this sea and shafts)."""
        for models, names in (([v.params for v in vessels], ("psi_w", "delta_max",
                                                              "delta_rate_max")),
                              (vessels, (*self.STATES, "delta"))):
            for name in names:
                getattr(self, name)[lanes] = [getattr(m, name) for m in models]
        for name, source in (WaveArrays.SOURCES.items() if self.waves is not None else ()):
            getattr(self.waves, name)[lanes] = [attrgetter(source)(v.waves) for v in vessels]

    def step(self, t: float | np.ndarray, h: float, delta_c: np.ndarray) -> None:
        """``Vessel.step`` (at each member's own t_k, if an array): two RK4 steps for the
        members whose rudder kinks in the step."""
        gear = RudderArrays(self.delta, delta_c, self.delta_max, self.delta_rate_max)
        y = tuple(getattr(self, name) for name in self.STATES)
        split = (0.0 < gear.reach) & (gear.reach < h)
        y = self._rk4(t, 0.0, np.where(split, gear.reach, h), y, gear, self.waves, self.psi_w)
        lanes = np.flatnonzero(split)
        if len(lanes) == len(split):
            y = self._rk4(t, gear.reach, h - gear.reach, y, gear, self.waves, self.psi_w)
        elif len(lanes):
            part = RudderArrays(self.delta[lanes], delta_c[lanes], self.delta_max[lanes],
                                self.delta_rate_max[lanes])
            rest = self._rk4(t if np.ndim(t) == 0 else t[lanes], part.reach, h - part.reach,
                             tuple(a[lanes] for a in y), part,
                             None if self.waves is None else self.waves.take(lanes),
                             self.psi_w[lanes])
            for whole, value in zip(y, rest):
                whole[lanes] = value
        for name, value in zip(self.STATES, y):
            setattr(self, name, value)
        self.delta = gear(h)

    def _rk4(self, t: float, start: np.ndarray | float, hs: np.ndarray, y: Arrays,
             gear: RudderArrays, waves: WaveArrays | None, psi_w: np.ndarray) -> Arrays:
        """``rk4_step`` of the members of ``waves``, ``psi_w`` and ``gear`` (all or some)."""
        v = self.vessel
        loads, hypot = (waves, exact.hypot) if waves is not None else (calm_water, _no_travel)

        def rates(t: np.ndarray | float, state: Arrays, tau_th: Arrays) -> Arrays:
            return state_rates(v.hull, v._minv, v._m11_inv, loads, psi_w, t, state, tau_th,
                               hypot, np.cos, np.sin)
        return rk4_step(rates, self.forces, gear, t, start + 0.0 * hs, hs, y, np.array_equal)
