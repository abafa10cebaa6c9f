"""The ship as a Gymnasium environment (issue 39): the single env passes Gymnasium's checker,
the vector env is a SyncVectorEnv of single envs bit for bit, the PD as a policy gives the
published J through either, and a trained policy's FMU steers as the env's policy did."""
from __future__ import annotations

import json
import math

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import cosim
from autopilot_fmu.policy import Policy
from cosim.analysis.metrics import cost
from cosim.ensemble.exact import tanh
from cosim.rl import ENV_ID
from cosim.rl.cem import PD, Settings, evaluate, returns, train
from cosim.rl.env import ShipEnv
from cosim.rl.policy_fmu import build_policy_fmu, checked_name
from cosim.rl.vector import ShipVectorEnv

SHORT_ROUTE = "0,0;5,0"
"""Within R_accept of its end after 8.4 s straight on, 8.7 s hard over: with a stop time of
8.5 s, one ship ends at the waypoint and the other at the stop time."""


@pytest.mark.filterwarnings("ignore:.*Box observation space m")   # unbounded: speeds, metres
def test_the_single_env_passes_gymnasiums_checker_on_either_route():
    envs = [ShipEnv("waves_pd", stop_time=5, backend=b) for b in ("inprocess", "fmi")]
    check_env(envs[0])
    assert [e.master.backends["ship"] for e in envs] == ["inprocess", "fmi"]
    steps = [np.concatenate([env.reset(seed=3)[0], *(np.append(*env.step([0.1 * k])[:2])
                                                     for k in range(-3, 4))]) for env in envs]
    assert steps[0].tobytes() == steps[1].tobytes()         # the FMUs give the same bits
    for env in envs:
        env.close()


@pytest.mark.parametrize("scenario", ["waves_pd", "calm_smc"])
def test_the_vector_env_is_a_sync_vector_env_of_single_envs_bit_for_bit(scenario):
    """Through truncations, terminations and their autoresets (next step, drawn seeds)."""
    options = {"num_envs": 3, "scenario": scenario, "stop_time": 8.5,
               "set": {"guidance.waypoints": SHORT_ROUTE}}
    ours = gymnasium.make_vec(ENV_ID, vectorization_mode="vector_entry_point", **options)
    sync = gymnasium.make_vec(ENV_ID, vectorization_mode="sync", **options)
    assert isinstance(ours, ShipVectorEnv)
    rng, ended = np.random.default_rng(5), np.zeros(2, int)
    first, _ = ours.reset(seed=7)
    np.testing.assert_array_equal(first, sync.reset(seed=7)[0])
    for _ in range(200):
        action = np.array([[rng.uniform(-0.02, 0.02)], [0.6], [rng.uniform(-0.3, 0.3)]])
        got, want = ours.step(action), sync.step(action)
        for mine, theirs in zip(got[:4], want[:4]):
            assert mine.tobytes() == theirs.tobytes()
        ended += [got[2].sum(), got[3].sum()]
    assert ended.all()                      # both ends met, and the restarts after them
    ours.close(), sync.close()


def test_episodes_end_at_the_last_waypoint_or_the_stop_time():
    env = ShipVectorEnv(2, "calm_pd", stop_time=8.5, set={"guidance.waypoints": SHORT_ROUTE})
    env.reset(seed=0)
    ends = {}
    for k in range(1, 87):
        _, paid, terminated, truncated, _ = env.step([[0.0], [0.6]])   # on, and turned away
        if k - 1 in ends.get(0, ()):
            assert paid[0] == 0.0 and not terminated[0]        # restarted, as next step
        for i in np.flatnonzero(terminated | truncated):
            ends.setdefault(i, []).append((k, "terminated" if terminated[i] else "truncated"))
    assert ends[0] == [(84, "terminated")] and ends[1] == [(85, "truncated")]
    env.close()


@pytest.mark.parametrize("scenario, seed", [     # quick: calm water; the waves: --long
    ("calm_pd", 0), pytest.param("waves_pd", 2010, marks=pytest.mark.long)])
def test_the_pd_as_a_policy_gives_the_published_J_through_either_env(scenario, seed):
    """waves_pd's own wave seed is 2010: reset(seed=2010) is its published run."""
    published = cost(cosim.simulate(scenario, backend="inprocess")).J
    single = ShipEnv(scenario, terminate=False)
    obs, _ = single.reset(seed=seed)
    total, done = 0.0, False
    while not done:
        obs, paid, terminated, truncated, _ = single.step([PD.act(obs[0], obs[1])])
        total, done = total + paid, terminated or truncated
    single.close()
    vector = evaluate({"pd": PD}, scenario, [seed])["pd"][0]
    assert math.isclose(-total, published, rel_tol=1e-12)
    assert math.isclose(vector, published, rel_tol=1e-12)


def test_actions_and_settings_are_refused_by_name():
    env = ShipVectorEnv(2, "calm_pd", stop_time=1)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action: delta_c = nan is not finite \(ship 1\)"):
        env.step([[0.0], [math.nan]])
    with pytest.raises(ValueError, match="seed: 3 seeds for 2 ships"):
        env.reset(seed=[1, 2, 3])
    with pytest.raises(ValueError, match="ship.wave_seed = 2147483648 is outside the range"):
        env.reset(seed=[0, 2**31])
    with pytest.raises(ValueError, match=r"action: 2 rudder commands delta_c \(shape \(2, 1\)\), "
                                         r"got shape \(3,\)"):
        env.step([0.0, 0.1, 0.2])
    for name, why in (("my-policy", "is not a Python identifier"), ("class", "is a Python "
                      "keyword"), ("json", "is the name of a Python module here")):
        with pytest.raises(ValueError, match=f"--name '{name}' {why}"):
            checked_name(name)
    with pytest.raises(ValueError, match="population: at least 4 candidates, got 3"):
        Settings(population=3)
    with pytest.raises(ValueError, match="num_envs must be a whole number >= 1, got 0"):
        ShipVectorEnv(0)
    with pytest.raises(ValueError, match="the batch kernel cannot step waves_pd_los: guidance "
                                         r"\(los_guidance.fmu\) is the model 'los_guidance'"):
        ShipVectorEnv(2, "waves_pd_los")
    with pytest.raises(ValueError, match="the batch kernel cannot step waves_pd_current: the "
                                         "batch route runs course keeping"):
        ShipVectorEnv(2, "waves_pd_current")
    with pytest.raises(ValueError, match="zigzag_10_10 has no autopilot to take the place of"):
        ShipEnv("zigzag_10_10")


@pytest.mark.parametrize("hidden", [(), (3,), (2, 2)])
def test_a_policy_gives_the_same_bits_as_floats_and_as_arrays_of_many(hidden):
    rng = np.random.default_rng(len(hidden))
    size = sum(i * o + o for i, o in Policy.sizes(hidden))
    theta, e, r = rng.normal(size=(size, 5)), rng.normal(size=5), rng.normal(size=5) * 0.01
    many = Policy.from_vector(list(theta), hidden, (0.1, 0.01)).act(e, r, tanh=tanh)
    for i in range(5):
        one = Policy.from_vector([float(x) for x in theta[:, i]], hidden, (0.1, 0.01))
        assert one.act(float(e[i]), float(r[i])) == many[i]
        assert Policy.from_json(one.to_json()) == one
    with pytest.raises(ValueError, match="policy: .* 9 parameters, not 3"):
        Policy.from_json(json.dumps({"hidden": [2], "scale": [1, 1], "theta": [1, 2, 3]}))


def test_a_trained_policy_steers_its_fmu_as_it_steered_the_env(fmu_paths, tmp_path):
    """In a host that ran the shipped policy's FMU first: pythonfmu runs every FMU in the
    host's one interpreter, so a trained FMU's model is named anew (its modules with it)."""
    settings = Settings("calm_pd", population=4, seeds=1, generations=2, stop_time=20)
    policy, curve = train(settings)
    assert len(curve.best) == 2 and curve.best[-1] <= curve.elites[-1]
    assert train(settings)[0] == policy                       # its draws are seeded
    shipped = cosim.simulate("calm_pd", fmu_paths["policy_autopilot"], stop_time=20)
    fmu = build_policy_fmu(policy, tmp_path / "trained_in_a_test.fmu", note="a test")
    run = cosim.simulate("calm_pd", fmu, stop_time=20)
    assert cost(run).J != cost(shipped).J
    with pytest.raises(ValueError, match="--name 'policy_autopilot' is the name of one of "):
        build_policy_fmu(policy, tmp_path / "policy_autopilot.fmu")
    env = ShipVectorEnv(1, "calm_pd", stop_time=20, terminate=False)
    assert cost(run).J == pytest.approx(returns(env, policy, [0])[0], rel=1e-12)
    env.close()


def test_stable_baselines3s_checker_passes_where_it_is_installed():
    checker = pytest.importorskip("stable_baselines3.common.env_checker")   # not a dependency
    env = ShipEnv("waves_pd", stop_time=5)
    checker.check_env(env)
    env.close()


@pytest.mark.long
@pytest.mark.timeout(300, method="thread")
def test_a_training_gives_the_same_policy_under_other_cpus_numpy():
    """The trainer's sums are exact and its sort stable: numpy's dispatch cannot move it."""
    import os
    import subprocess
    import sys

    from cosim.studies.cpu_variants import VARIANTS
    child = ("from cosim.rl.cem import Settings, train; print(train(Settings('waves_pd', (3,), "
             "6, 1, 3, stop_time=30))[0].to_json())")
    policies = {name: subprocess.run([sys.executable, "-c", child], capture_output=True,
                                     text=True, timeout=240, env={**os.environ, **extra},
                                     check=True).stdout
                for name, extra in VARIANTS.items() if name.startswith(("default", "numpy"))}
    assert len(policies) == 3 and len(set(policies.values())) == 1, policies
