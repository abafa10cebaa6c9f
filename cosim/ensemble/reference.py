"""The scalar models stepped as the master steps them (Gauss-Seidel, guidance -> autopilot ->
ship): the reference the batch kernel is pinned to, and what ``cosim.bench`` times as (a)."""
from __future__ import annotations

from typing import Any

import numpy as np

from fmukit.timebase import communication_point

from ..core.master import Master
from .members import COMPONENTS, initialise

SIGNALS = ("guidance.psi_d", "guidance.wp_index", "autopilot.delta_c", "ship.x", "ship.y",
           "ship.psi", "ship.u", "ship.v", "ship.r", "ship.delta")   # wave loads aside


def step_models(guidance: Any, autopilot: Any, ship: Any, shafts: tuple[float, float, float],
                t0: float, h: float, n_steps: int) -> dict[str, np.ndarray]:
    """Each of ``SIGNALS`` at t_0 .. t_N of initialised models, shafts (n1, n2, n3) held."""
    stepping_pilot = hasattr(autopilot, "step")
    pid = type(autopilot).__name__ == "PIDAutopilot"      # steps with its inputs, as its slave
    out = np.empty((n_steps + 1, len(SIGNALS)))
    for k in range(n_steps + 1):
        t = communication_point(t0, k, h)
        psi_d = guidance.psi_d(ship.x, ship.y)
        wp_index = guidance.wp_index(ship.x, ship.y)
        delta_c = autopilot.command(ship.psi, ship.r, psi_d)
        out[k] = (psi_d, wp_index, delta_c, ship.x, ship.y, ship.psi, ship.u, ship.v, ship.r,
                  ship.delta)
        if k == n_steps:
            break
        guidance.update(ship.x, ship.y)
        if pid:
            autopilot.step(h, ship.psi, ship.r, psi_d)
        elif stepping_pilot:
            autopilot.step(t, h, psi_d)
        ship.step(t, h, delta_c, *shafts)
    return dict(zip(SIGNALS, out.T))


def run_direct(master: Master, stop_time: float | None = None) -> dict[str, np.ndarray]:
    """``SIGNALS`` of the models ``master`` (in-process) initialises, stepped by hand: without
    the master's calls, records and checks."""
    t0, h, n_steps = master.system.steps(stop_time)
    member = initialise(master, master.overrides, n_steps)
    if member is None:
        raise RuntimeError(f"{master.system.name}: its models cannot be stepped by hand")
    return step_models(*(member.models[n] for n in COMPONENTS), member.shafts, t0, h, n_steps)
