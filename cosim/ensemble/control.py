"""The guidance (eq 18) and autopilots (eqs 20, 37-44) of ``autopilot_fmu`` on (M,) arrays,
built from the initialised scalar models; each member keeps its route (padded) and gains."""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from autopilot_fmu.guidance import WaypointGuidance
from autopilot_fmu.pd import PDAutopilot
from autopilot_fmu.smc import SlidingModeAutopilot, reference_acceleration, reference_rk4
from fmukit.numerics import substeps

from .exact import hypot, tanh, wrap


def _column(models: Sequence, name: str) -> np.ndarray:
    return np.array([getattr(m, name) for m in models], dtype=float)


class GuidanceArrays:
    """The active leg of every member's route, switched as ``WaypointGuidance`` does."""

    def __init__(self, guidances: Sequence[WaypointGuidance]):
        legs = max(len(g.points) for g in guidances) - 1
        self.points = np.array([len(g.points) for g in guidances])
        route = np.zeros((len(guidances), legs + 1, 2))
        course, length = np.zeros((len(guidances), legs)), np.ones((len(guidances), legs))
        for i, g in enumerate(guidances):
            route[i, :len(g.points)] = g.points
            for leg in range(len(g.points) - 1):
                (x0, y0), (x1, y1) = g.points[leg], g.points[leg + 1]
                course[i, leg] = g.course(leg)
                length[i, leg] = math.hypot(x1 - x0, y1 - y0)
        self.start, self.end = route[:, :-1], route[:, 1:]
        self.delta = self.end - self.start                  # (dx, dy) of each leg
        self.course, self.length = course, length
        self.R_accept = _column(guidances, "R_accept")
        self.leg = np.array([g.leg for g in guidances])
        self.finished = np.array([g.finished for g in guidances])
        self.members = np.arange(len(guidances))

    def _reached(self, leg: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        i = self.members
        (x0, y0), (x1, y1) = self.start[i, leg].T, self.end[i, leg].T
        dx, dy = self.delta[i, leg].T
        length = self.length[i, leg]
        along = ((x - x0) * dx + (y - y0) * dy) / length
        return _within(x1 - x, y1 - y, self.R_accept) | (along >= length)

    def active_leg(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(leg, finished) of every member at (x, y), from the committed legs onward."""
        leg, finished = self.leg.copy(), self.finished.copy()
        moving = ~finished
        while moving.any():
            moving &= self._reached(leg, x, y)
            last = leg + 2 >= self.points
            finished |= moving & last
            leg = np.where(moving & ~last, leg + 1, leg)
            moving &= ~last
        return leg, finished

    def outputs(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(psi_d, wp_index) at (x, y), the leg switches committed."""
        self.leg, self.finished = self.active_leg(x, y)
        psi_d = self.course[self.members, self.leg]
        return psi_d, np.where(self.finished, self.points, self.leg + 1)


NEAR = 1e-12           # relative distance from the circle within which math.hypot decides


def _within(dx: np.ndarray, dy: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """``math.hypot(dx, dy) <= radius``, by the cheaper ``np.hypot`` away from the circle."""
    distance = np.hypot(dx, dy)
    inside = distance <= radius
    near = np.abs(distance - radius) <= NEAR * radius
    if near.any():
        inside[near] = hypot(dx[near], dy[near]) <= radius[near]
    return inside


class PDArrays:
    """``PDAutopilot.command``, eq (20): memoryless."""

    def __init__(self, pilots: Sequence[PDAutopilot]):
        self.Kp, self.Kd = _column(pilots, "Kp"), _column(pilots, "Kd")

    def command(self, psi: np.ndarray, r: np.ndarray, psi_d: np.ndarray) -> np.ndarray:
        return self.Kp * wrap(psi - psi_d) + self.Kd * r

    def step(self, t: float, h: float, psi: np.ndarray, r: np.ndarray,
             psi_d: np.ndarray) -> None:
        pass


class PIDArrays:
    """``PIDAutopilot`` (pid_autopilot_slave): eq (20) with conditional integration."""

    def __init__(self, pilots: Sequence):
        for name in ("Kp", "Ki", "Kd", "delta_max", "e_int", "z"):
            setattr(self, name, _column(pilots, name))

    def command(self, psi: np.ndarray, r: np.ndarray, psi_d: np.ndarray) -> np.ndarray:
        return self.Kp * wrap(psi - psi_d) + self.Ki * self.z + self.Kd * r

    def step(self, t: float, h: float, psi: np.ndarray, r: np.ndarray,
             psi_d: np.ndarray) -> None:
        e, u = wrap(psi - psi_d), self.command(psi, r, psi_d)
        integrate = (np.abs(e) < self.e_int) & ((np.abs(u) < self.delta_max) | (u * e < 0.0))
        self.z = np.where(integrate, self.z + e * h, self.z)


class SMCArrays:
    """``SlidingModeAutopilot``: the law (37)-(43) and the reference model (44) by RK4."""

    def __init__(self, pilots: Sequence[SlidingModeAutopilot]):
        self.k1, self.k2 = (np.array([p.design.K[j] for p in pilots]) for j in (0, 1))
        self.h1, self.h2 = (np.array([p.design.h[j] for p in pilots]) for j in (0, 1))
        self.tracking = np.array([p.tracking for p in pilots])
        for name in ("eta_h", "phi_h", "omega_n", "zeta", "psi_z", "r_z", "_h_max"):
            setattr(self, name.lstrip("_"), _column(pilots, name))
        self._cuts: tuple[float, np.ndarray] | None = None

    def command(self, psi: np.ndarray, r: np.ndarray, psi_d: np.ndarray) -> np.ndarray:
        error = wrap(self.psi_z - psi)
        u_eq = self.k1 * error + self.k2 * (np.where(self.tracking, self.r_z, 0.0) - r)
        sigma = self.h1 * error + self.h2 * (self.r_z - r)
        r_z_dot = reference_acceleration(psi_d, self.psi_z, self.r_z, self.omega_n,
                                         self.zeta, wrap)
        u_sw = self.h1 * self.r_z + self.h2 * r_z_dot - self.eta_h * tanh(sigma / self.phi_h)
        return u_eq + u_sw

    def step(self, t: float, h: float, psi: np.ndarray, r: np.ndarray,
             psi_d: np.ndarray) -> None:
        if self._cuts is None or self._cuts[0] != h:
            self._cuts = h, np.array([substeps(h, bound, "of the reference model")
                                      for bound in self.h_max])
        n = self._cuts[1]
        hs = h / n
        psi_z, r_z = self.psi_z, self.r_z
        for j in range(int(n.max())):
            stepped = reference_rk4(psi_d, psi_z, r_z, hs, self.omega_n, self.zeta, wrap)
            active = j < n
            psi_z, r_z = (np.where(active, new, old) for new, old in zip(stepped, (psi_z, r_z)))
        self.psi_z, self.r_z = psi_z, r_z


def autopilot_arrays(pilots: Sequence) -> PDArrays | PIDArrays | SMCArrays:
    """The array form of the members' autopilots, all of one kind; ValueError otherwise."""
    kinds = {type(p).__name__ for p in pilots}
    if len(kinds) != 1 or next(iter(kinds)) not in KINDS:
        raise ValueError(f"the batch route runs one of {', '.join(KINDS)} for every member, "
                         f"not {', '.join(sorted(kinds))}")
    return KINDS[kinds.pop()](pilots)


KINDS = {"PDAutopilot": PDArrays, "PIDAutopilot": PIDArrays,   # by class name: the PID's
         "SlidingModeAutopilot": SMCArrays}                    # lives in its slave
