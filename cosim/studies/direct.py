"""The paper's diagram wired by hand from the plain modules, without FMI or master: guidance ->
autopilot -> ship at every step (``cosim.ensemble.reference.step_models``), the models built
by the FMUs' own code from a course-keeping system's parameters. The benchmark's in-process
limit, the tests' reference, and the monolithic model's start."""
from __future__ import annotations

import numpy as np

from fmukit.timebase import step_count
from ship_fmu.vessel import N_PROPELLER

from ..core.inprocess import InProcessInstance
from ..core.ssd import SystemDescription
from ..ensemble.reference import step_models


def build_models(system: SystemDescription) -> dict:
    """Each component's model, built from the system's parameters by its slave class."""
    ship_start = system.components["ship"].parameters
    models = {}
    for name, component in system.components.items():
        instance = InProcessInstance(system.fmu_path(name), name, same_sources=False)
        instance.enter_initialization(system.start_time)
        instance.set(component.parameters)
        if name == "autopilot":             # the reference model starts at the ship's state
            instance.set({"psi": ship_start.get("psi0", 0.0), "r": ship_start.get("r0", 0.0)})
        instance.exit_initialization(system.start_time)
        models[name] = instance.slave.model
    return models


def shaft_speeds(system: SystemDescription) -> tuple[float, float, float]:
    """The ship's propeller and bow thruster speeds n1, n2, n3 as the system sets them."""
    inputs = system.components["ship"].parameters
    return tuple(inputs.get(n, N_PROPELLER if n != "n3" else 0.0) for n in ("n1", "n2", "n3"))


def run_direct(system: SystemDescription, stop_time: float | None = None) -> dict[str, np.ndarray]:
    """Each signal of ``SIGNALS`` at t_k = k h, k = 0 .. N, like the master's rows."""
    models = build_models(system)
    h, t0 = system.step_size, system.start_time
    n_steps = step_count(t0, system.stop_time if stop_time is None else stop_time, h)
    return step_models(*(models[n] for n in ("guidance", "autopilot", "ship")),
                       shaft_speeds(system), t0, h, n_steps)
