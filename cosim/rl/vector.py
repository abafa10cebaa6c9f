"""M ships as one Gymnasium vector environment on the batch kernel (``cosim.ensemble``): each
step one numpy call per model for all, each ship bit for bit ``ShipEnv`` with the same seed
and actions (tests/test_rl.py); autoreset as Gymnasium 1.x's next step."""
from __future__ import annotations

import warnings
from typing import Any, Sequence

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv

from fmukit.timebase import communication_point

from .. import scenarios
from ..analysis.metrics import LAMBDA
from ..api import overrides_of
from ..core.master import Master
from ..ensemble import selftest
from ..ensemble.route import cut
from ..ensemble.control import GuidanceArrays
from ..ensemble.reference import coverage
from ..ensemble.vessel import VesselArrays
from .spaces import (MAX_SEED, SIGNALS, action_space, finished, observation_space, observe,
                     open_loop, reward, rudder_commands, seeded, short)


class ShipVectorEnv(VectorEnv):
    """``num_envs`` ships of one scenario and settings in lockstep, each its own wave seed:
    ``reset(seed=s)`` gives ship i the seed s + i (a list: one each), as Gymnasium's
    SyncVectorEnv of ``ShipEnv`` would."""
    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs: int, scenario: str = "calm_pd",
                 set: dict[str, Any] | None = None, stop_time: float | None = None,
                 lam: float = LAMBDA, terminate: bool = True, fmi: int | None = None):
        if isinstance(num_envs, bool) or not isinstance(num_envs, int) or num_envs < 1:
            raise ValueError(f"num_envs must be a whole number >= 1, got {num_envs!r}")
        self.num_envs, self.lam, self.terminate = num_envs, lam, terminate
        self.overrides = overrides_of(set or {})
        loaded = scenarios.load(scenario, fmi=fmi)
        system = open_loop(loaded)
        if (why := coverage(loaded)) is not None:       # LOS guidance, a current: not in it
            raise ValueError(f"the batch kernel cannot step {loaded.name}: {why}; ShipEnv "
                             "steps it through the FMUs (or Gymnasium's SyncVectorEnv of it)")
        self.master = Master(system, backend="inprocess", overrides=self.overrides)
        t0, self.h, self.n_steps = self.master.system.steps(stop_time)
        self.times = np.array([communication_point(t0, k, self.h)
                               for k in range(self.n_steps + 1)])
        vessel, _ = self._member(0)
        ship = self.master.instances["ship"].slave
        self.shafts = (ship.n1, ship.n2, ship.n3)                # held, as in the scenario
        if (why := cut(vessel, self.h)) is not None:
            raise ValueError(why)
        if (why := selftest()) is not None:
            warnings.warn(f"{why}: the ships' last bits may differ from ShipEnv's", stacklevel=2)
        delta_max = vessel.params.delta_max
        self.single_observation_space = observation_space(delta_max)
        self.single_action_space = action_space(delta_max)
        self.observation_space = observation_space(delta_max, num_envs)
        self.action_space = action_space(delta_max, num_envs)

    def _member(self, wave_seed: int) -> tuple[Any, Any]:
        """The ship and guidance models of one ship, initialised by the in-process master."""
        self.master.reset()
        self.master.configure(seeded(self.overrides, wave_seed))
        self.master.initialize()
        return tuple(self.master.instances[n].slave.model for n in ("ship", "guidance"))

    def _seeds(self, lanes: Sequence[int]) -> list[int]:
        return [int(self.rngs[i].integers(MAX_SEED + 1)) for i in lanes]

    def reset(self, *, seed: int | Sequence[int] | None = None, options: dict | None = None):
        seeds = ([None] * self.num_envs if seed is None else
                 [seed + i for i in range(self.num_envs)] if isinstance(seed, int) else list(seed))
        if len(seeds) != self.num_envs:
            raise ValueError(f"seed: {len(seeds)} seeds for {self.num_envs} ships")
        self.rngs = [seeding.np_random(s)[0] for s in seeds]
        members = [self._member(s if s is not None else self._seeds([i])[0])
                   for i, s in enumerate(seeds)]
        self.ship = VesselArrays([v for v, _ in members], self.shafts)
        self.route = GuidanceArrays([g for _, g in members])
        self.k, self.ended = np.zeros(self.num_envs, int), np.zeros(self.num_envs, bool)
        s = self._signals()
        self.first = -reward(s, self.lam, 0.0)
        return observe(self.route, s), {"t": self.times[self.k]}

    def _signals(self) -> dict[str, np.ndarray]:
        psi_d, wp_index = self.route.outputs(self.ship.x, self.ship.y)   # legs switched
        return {"psi_d": psi_d, "wp_index": wp_index,
                **{short(n): getattr(self.ship, short(n)) for n in SIGNALS[2:]}}

    def step(self, actions: Any):
        delta_c = rudder_commands(actions, self.num_envs)
        self.ship.step(self.times[self.k], self.h, delta_c)
        self.k += 1
        restart = np.flatnonzero(self.ended)        # ended last step: start afresh instead
        if len(restart):
            members = [self._member(s) for s in self._seeds(restart)]
            self.ship.put(restart, [v for v, _ in members])
            self.route.put(restart, [g for _, g in members])
            self.k[restart] = 0
        s = self._signals()
        paid = reward(s, self.lam, np.where(self.k == 1, self.first, 0.0))
        if len(restart):
            self.first[restart] = -reward(s, self.lam, 0.0)[restart]
            paid[restart] = 0.0
        terminated = self.terminate & finished(self.route, s) & ~self.ended
        truncated = (self.k >= self.n_steps) & ~self.ended
        self.ended = terminated | truncated
        return observe(self.route, s), paid, terminated, truncated, {"t": self.times[self.k]}

    def close(self, **kwargs: Any) -> None:
        self.master.free()
