"""The guidance (eq 18) and autopilots (eqs 20, 37-44) of ``autopilot_fmu`` on (M,) arrays,
built from the initialised scalar models; each member keeps its route (padded) and gains."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from autopilot_fmu.guidance import WaypointGuidance, leg_offsets
from autopilot_fmu.pd import PDAutopilot
from autopilot_fmu.smc import SlidingModeAutopilot, reference_acceleration, reference_rk4

from .exact import hypot, tanh, wrap

NEAR = 1e-12           # relative distance from the circle within which math.hypot decides


def columns(target: object, models: Sequence, names: tuple[str, ...], dtype=float) -> None:
    """Each attribute ``name`` of the models as an (M,) array (a leading _ dropped)."""
    for name in names:
        setattr(target, name.lstrip("_"), np.array([getattr(m, name) for m in models], dtype))


class GuidanceArrays:
    """The active leg of every member's route, switched as ``WaypointGuidance`` does."""

    def __init__(self, guidances: Sequence[WaypointGuidance]):
        count, legs = len(guidances), max(len(g.points) for g in guidances) - 1
        route, self.course = np.zeros((count, legs + 1, 2)), np.zeros((count, legs))
        for i, g in enumerate(guidances):
            route[i, :len(g.points)] = g.points
            self.course[i, :len(g.points) - 1] = [g.course(leg) for leg in range(len(g.points) - 1)]
        self.start, self.end = route[:, :-1], route[:, 1:]
        self.delta = self.end - self.start                  # (dx, dy) of each leg
        self.length = hypot(self.delta[..., 0], self.delta[..., 1])   # 0 past a route's end
        self.points = np.array([len(g.points) for g in guidances])
        self.R_accept = np.array([g.R_accept for g in guidances], dtype=float)
        columns(self, guidances, ("leg", "finished"), None)
        self.members = np.arange(count)

    def put(self, lanes: np.ndarray, guidances: Sequence[WaypointGuidance]) -> None:
        """Lanes ``lanes`` start afresh with ``guidances`` (initialised, on the same route)."""
        self.leg[lanes] = [g.leg for g in guidances]
        self.finished[lanes] = [g.finished for g in guidances]

    def outputs(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(psi_d, wp_index) at (x, y), the leg switches (``WaypointGuidance``) committed."""
        i, leg, finished = self.members, self.leg, self.finished.copy()
        moving = ~finished
        while moving.any():
            (x0, y0), (x1, y1), (dx, dy) = (a[i, leg].T for a in (self.start, self.end, self.delta))
            length = self.length[i, leg]
            along = leg_offsets(x, y, x0, y0, dx, dy, length)[1]
            moving &= _within(x1 - x, y1 - y, self.R_accept) | (along >= length)
            last = leg + 2 >= self.points
            finished |= moving & last
            leg = np.where(moving & ~last, leg + 1, leg)
            moving &= ~last
        self.leg, self.finished = leg, finished
        return self.course[i, leg], np.where(finished, self.points, leg + 1)


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
        columns(self, pilots, ("Kp", "Kd"))

    def command(self, psi: np.ndarray, r: np.ndarray, psi_d: np.ndarray) -> np.ndarray:
        return self.Kp * wrap(psi - psi_d) + self.Kd * r

    def step(self, *args: object) -> None:
        """Memoryless: nothing to step."""


class PIDArrays:
    """``PIDAutopilot`` (pid_autopilot_slave): eq (20) with conditional integration."""

    def __init__(self, pilots: Sequence):
        columns(self, pilots, ("Kp", "Ki", "Kd", "delta_max", "e_int", "z"))

    def command(self, psi: np.ndarray, r: np.ndarray, psi_d: np.ndarray) -> np.ndarray:
        return self.Kp * wrap(psi - psi_d) + self.Ki * self.z + self.Kd * r

    def step(self, t: float, h: float, psi: np.ndarray, r: np.ndarray,
             psi_d: np.ndarray) -> None:
        e, u = wrap(psi - psi_d), self.command(psi, r, psi_d)
        integrate = (np.abs(e) < self.e_int) & ((np.abs(u) < self.delta_max) | (u * e < 0.0))
        self.z = np.where(integrate, self.z + e * h, self.z)


class SMCArrays:
    """``SlidingModeAutopilot``: the law (37)-(43) and the reference model (44) by RK4, of
    members whose reference model takes the step whole."""

    def __init__(self, pilots: Sequence[SlidingModeAutopilot]):
        self.k1, self.k2 = (np.array([p.design.K[j] for p in pilots]) for j in (0, 1))
        self.h1, self.h2 = (np.array([p.design.h[j] for p in pilots]) for j in (0, 1))
        self.tracking = np.array([p.tracking for p in pilots])
        columns(self, pilots, ("eta_h", "phi_h", "omega_n", "zeta", "psi_z", "r_z"))

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
        self.psi_z, self.r_z = reference_rk4(psi_d, self.psi_z, self.r_z, h, self.omega_n,
                                             self.zeta, wrap)


KINDS = {"PDAutopilot": PDArrays, "PIDAutopilot": PIDArrays,   # by class name: the PID's
         "SlidingModeAutopilot": SMCArrays}                    # lives in its slave
