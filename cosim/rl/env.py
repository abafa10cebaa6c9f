"""One ship as a Gymnasium environment: the scenario's guidance and ship FMUs stepped by the
master at its step (0.1 s), through FMI or in-process, the agent in the autopilot's place."""
from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np

from autopilot_fmu.guidance import WaypointGuidance, route
from fmukit.timebase import communication_point
from ship_fmu.vessel import VesselParameters

from .. import scenarios
from ..analysis.metrics import LAMBDA
from ..api import overrides_of
from ..core.master import Master
from ..core.wiring import communication_step
from ..ensemble.control import GuidanceArrays
from .spaces import (MAX_SEED, SIGNALS, action_space, finished, observation_space, observe,
                     open_loop, reward, rudder_commands, seeded, short)


class ShipEnv(gymnasium.Env):
    """Action: the ship's commanded rudder delta_c, rad; observation and reward: docs/rl.md.
    ``reset(seed=s)`` runs the wave realisation ``ship.wave_seed = s``, as a sweep's seed s."""
    metadata = {"render_modes": []}

    def __init__(self, scenario: str = "calm_pd", set: dict[str, Any] | None = None,
                 stop_time: float | None = None, backend: str = "inprocess",
                 lam: float = LAMBDA, terminate: bool = True, fmi: int | None = None):
        self.overrides = overrides_of(set or {})
        self.master = Master(open_loop(scenarios.load(scenario, fmi=fmi)), backend=backend,
                             overrides=self.overrides)
        self.t0, self.h, self.n_steps = self.master.system.steps(stop_time)
        self.lam, self.terminate, self._started = lam, terminate, False
        self.where = [self.master.columns.index(s) for s in SIGNALS]
        delta_max = self._setting("ship", "delta_max")
        self.observation_space = observation_space(delta_max)
        self.action_space = action_space(delta_max)

    def _setting(self, component: str, name: str) -> Any:
        return self.master.parameters[component].get(name, getattr(VesselParameters, name))

    def _signals(self) -> dict[str, np.ndarray]:
        return {short(s): np.array([self.values[j]]) for s, j in zip(SIGNALS, self.where)}

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        wave_seed = seed if seed is not None else int(self.np_random.integers(MAX_SEED + 1))
        if self._started:
            self.master.reset()
        self.master.configure(seeded(self.overrides, wave_seed))
        self.master.initialize()
        self._started, self.k = True, 0
        guidance = self.master.parameter_values["guidance"]
        self.route = GuidanceArrays([WaypointGuidance(route(guidance), guidance["R_accept"])])
        self.values = [0.0] * len(self.master.columns)
        communication_step(self.master.nodes, self.values, self.t0, self.h, False)
        s = self._signals()
        self.first = -reward(s, self.lam, 0.0)[0]       # t_0's share, paid with step 1
        return observe(self.route, s)[0], {"t": self.t0}

    def step(self, action: Any):
        delta_c = float(rudder_commands(action, 1)[0])
        t = communication_point(self.t0, self.k, self.h)
        self.master.instances["ship"].set({"delta_c": delta_c}, time=t)
        communication_step(self.master.nodes, self.values, t, self.h, True)
        self.k += 1
        t = communication_point(self.t0, self.k, self.h)
        communication_step(self.master.nodes, self.values, t, self.h, False)
        s = self._signals()
        paid = reward(s, self.lam, self.first if self.k == 1 else 0.0)[0]
        done = bool(self.terminate and finished(self.route, s)[0])
        return (observe(self.route, s)[0], float(paid), done, self.k >= self.n_steps,
                {"t": t})

    def close(self) -> None:
        self.master.free()
