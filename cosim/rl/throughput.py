"""``python -m cosim.bench rl``: env steps per second of ``ShipVectorEnv`` against Gymnasium's
``SyncVectorEnv`` of ``ShipEnv`` (in-process), side by side (printed, never asserted)."""
from __future__ import annotations

import numpy as np
from gymnasium.vector import SyncVectorEnv

from ..studies.timing import machine, side_by_side
from .env import ShipEnv
from .vector import ShipVectorEnv

COUNTS = (256, 1000)
STEPS = {"vector": 40, "sync": 4}       # env steps per timed run, each of M ships


def throughput(counts: tuple[int, ...] = COUNTS, repeats: int = 3) -> dict[tuple, float]:
    """The ratio of the two envs' env steps per second, by (scenario, M)."""
    print(f"RL environments: env steps per second (M ships each step; median of {repeats} "
          f"runs taken in turn), on {machine()}")
    ratios = {}
    for scenario in ("calm_pd", "waves_pd"):
        for count in counts:
            envs = {"vector": ShipVectorEnv(count, scenario),
                    "sync": SyncVectorEnv([lambda: ShipEnv(scenario)] * count)}
            action = np.zeros((count, 1))
            for env in envs.values():
                env.reset(seed=0)
            times = side_by_side({k: lambda env=env, k=k: [env.step(action) for _ in range(
                STEPS[k])] for k, env in envs.items()}, repeats)
            rate = {k: count * STEPS[k] / seconds for k, seconds in times.items()}
            ratios[scenario, count] = rate["vector"] / rate["sync"]
            print(f"  {scenario}, M = {count:5}: ShipVectorEnv {rate['vector']:10,.0f}/s, "
                  f"SyncVectorEnv of ShipEnv {rate['sync']:8,.0f}/s: "
                  f"{ratios[scenario, count]:5.1f}x")
            for env in envs.values():
                env.close()
    return ratios
