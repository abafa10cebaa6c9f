"""Which systems the batch kernel runs, and each member's models initialised by the in-process
master exactly as a run of it would be."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from fmukit.manifest import read as read_manifest

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
