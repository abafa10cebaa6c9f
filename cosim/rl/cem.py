"""A policy (``autopilot_fmu.policy``) trained on ``ShipVectorEnv`` by the cross-entropy
method, numpy only: each generation's candidates, each on the same few wave seeds, are one
batch of the vector env; the next generation is drawn around the best quarter."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from autopilot_fmu.policy import FEATURES, Policy

from ..ensemble.exact import tanh
from .spaces import OBSERVATION
from .vector import ShipVectorEnv

PD = Policy.from_vector([2.0, 50.0, 0.0], (), (1.0, 1.0))   # eq (20) as a policy: Kp, Kd
COLUMNS = [list(OBSERVATION).index(f) for f in FEATURES]     # the policy's inputs
TRAIN_SEEDS = 10_000            # generation g trains on wave seeds 10,000 + g S .. + S - 1


@dataclass(frozen=True)
class Settings:
    scenario: str = "waves_pd"
    hidden: tuple[int, ...] = (8,)         # tanh layers; () is linear: a PD with a bias
    population: int = 32                   # candidates per generation
    seeds: int = 4                         # wave seeds each candidate is scored on
    generations: int = 40
    elite: float = 0.25                    # the fraction the next generation is drawn around
    scale: tuple[float, float] = (0.1, 0.01)   # e, r divided by these (rad, rad/s)
    seed: int = 0                          # of the candidates' draws
    stop_time: float | None = None

    def __post_init__(self) -> None:
        if self.population < 4:
            raise ValueError(f"population: at least 4 candidates, got {self.population} (the "
                             "next generation is drawn around the best quarter, at least two)")


@dataclass
class Curve:
    """Per generation: the best candidate's and the elites' mean J over the seeds, rad^2."""
    best: list[float] = field(default_factory=list)
    elites: list[float] = field(default_factory=list)


def returns(env: ShipVectorEnv, policy: Policy, seeds: Sequence[int]) -> np.ndarray:
    """J of each ship (minus its return) on ``seeds``, steered by ``policy`` (its weights
    floats, or arrays of one per ship) to the stop time."""
    obs, _ = env.reset(seed=list(seeds))
    total = np.zeros(env.num_envs)
    while True:
        obs, paid, terminated, truncated, _ = env.step(
            policy.act(*obs.T[COLUMNS], tanh=tanh)[:, None])
        total += paid
        if (terminated | truncated).all():
            return -total


def average(values: Sequence[float]) -> float:
    """The mean, exactly rounded (``math.fsum``): numpy's sums round by CPU."""
    return math.fsum(values) / len(values)


def train(settings: Settings, progress: Callable[[int, Curve], None] = lambda g, c: None
          ) -> tuple[Policy, Curve]:
    """The mean of the last generation's elites, and the learning curve."""
    s = settings
    size = Policy.count(s.hidden)
    rng = np.random.default_rng(s.seed)
    mean, std = np.zeros(size), np.full(size, 0.5)
    keep = max(2, round(s.elite * s.population))
    env = ShipVectorEnv(s.population * s.seeds, s.scenario, stop_time=s.stop_time,
                        terminate=False)
    curve = Curve()
    try:
        for g in range(s.generations):
            theta = mean[:, None] + std[:, None] * rng.standard_normal((size, s.population))
            lanes = np.repeat(theta, s.seeds, axis=1)               # candidate-major
            seeds = [TRAIN_SEEDS + g * s.seeds + j for j in range(s.seeds)] * s.population
            J = returns(env, Policy.from_vector(list(lanes), s.hidden, s.scale), seeds)
            score = np.array([average(row) for row in J.reshape(s.population, s.seeds)])
            order = np.argsort(score, kind="stable")[:keep]
            elites = theta[:, order]
            mean = np.array([average(row) for row in elites])
            std = np.sqrt([average((row - m) ** 2) for row, m in zip(elites, mean)])
            std += 0.02 * 0.9 ** g                  # a floor that shrinks: no early collapse
            curve.best.append(float(score[order[0]]))
            curve.elites.append(average(score[order]))
            progress(g, curve)
    finally:
        env.close()
    return Policy.from_vector([float(x) for x in mean], s.hidden, s.scale), curve


def evaluate(policies: dict[str, Policy], scenario: str, seeds: Sequence[int],
             stop_time: float | None = None) -> dict[str, np.ndarray]:
    """Each policy's J on each of ``seeds``, rad^2."""
    env = ShipVectorEnv(len(seeds), scenario, stop_time=stop_time, terminate=False)
    try:
        return {name: returns(env, policy, seeds) for name, policy in policies.items()}
    finally:
        env.close()

