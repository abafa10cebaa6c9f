"""The scalar models stepped as the master steps them (guidance -> autopilot -> ship): the
batch kernel's reference and ``cosim.bench``'s (a); which systems the kernel runs."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from fmukit.manifest import read as read_manifest
from fmukit.timebase import communication_point

from ..core.inprocess import fallback_note
from ..core.instance import FmuCallError
from ..core.master import Master, run_meta
from ..core.ssd import SystemDescription

COMPONENTS = ("guidance", "autopilot", "ship")
WIRING = frozenset({("guidance", "psi_d", "autopilot", "psi_d"),
                    ("ship", "psi", "autopilot", "psi"), ("ship", "r", "autopilot", "r"),
                    ("autopilot", "delta_c", "ship", "delta_c"),
                    ("ship", "x", "guidance", "x"), ("ship", "y", "guidance", "y")})
MODELS = {"guidance": ("guidance",), "ship": ("ship",),     # the models with array forms
          "autopilot": ("pd_autopilot", "pid_autopilot", "smc_autopilot")}


def coverage(system: SystemDescription) -> str | None:
    """Why the batch kernel cannot run ``system`` (course keeping of this project's FMUs)."""
    names = set(system.components)
    if system.events:
        return "the batch route has no timed events"
    if names != set(COMPONENTS):
        return (f"the batch route runs course keeping (guidance, autopilot, ship), not "
                f"{', '.join(sorted(names))}")
    wiring = {(c.start_element, c.start_connector, c.end_element, c.end_connector)
              for c in system.connections}
    if wiring != WIRING:
        return "its connections are not the course-keeping loop of cosim/scenarios"
    for name in COMPONENTS:
        path = system.fmu_path(name)
        note = fallback_note(name, path)
        if note is not None:
            return str(note)
        model = read_manifest(path).model_name
        if model not in MODELS[name]:
            return (f"{name} ({path.name}) is the model '{model}', which the batch kernel has "
                    f"no array form of (it has: {', '.join(MODELS[name])})")
    return None


@dataclass
class Member:
    """One member as the in-process master initialised it."""
    models: dict[str, Any]              # component: its model (Vessel, WaypointGuidance, ...)
    shafts: tuple[float, float, float]  # the ship's n1, n2, n3
    meta: dict[str, Any]                # what Master.run records about the run


def initialise(master: Master, overrides: dict[str, dict[str, Any]],
               n_steps: int) -> Member | None:
    """The member of ``overrides`` initialised by ``master``; None if that fails."""
    master.reset()
    master.configure(overrides)
    try:
        master.initialize()
    except FmuCallError:
        return None
    ship = master.instances["ship"].slave
    return Member({name: master.instances[name].slave.model for name in COMPONENTS},
                  (ship.n1, ship.n2, ship.n3),
                  {**run_meta(master, n_steps), "parameters": master.parameter_values})

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
