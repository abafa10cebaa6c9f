"""The batch kernel (cosim.ensemble) against the scalar models: every signal of every member
bit for bit equal to the in-process master's run of it, in every course-keeping scenario."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cosim import scenarios
from cosim.core.master import Master
from cosim.ensemble import exact, selftest, simulate_members
from cosim.ensemble.reference import SIGNALS
from fmukit.numerics import wrap

COURSE_KEEPING = ("calm_pd", "waves_pd", "calm_pid", "waves_pid", "calm_smc", "waves_smc")


def in_process(system, overrides: dict, stop_time: float):
    with Master(system, backend="inprocess") as master:
        master.configure(overrides)
        return master.run(stop_time)


def assert_same(batch, scalar, what: str) -> None:
    assert batch.error == scalar.error, what
    for signal in batch.columns:
        ours, theirs = batch[signal], scalar[signal]
        if ours.tobytes() != theirs.tobytes():
            k = int(np.flatnonzero(~((ours == theirs) | (np.isnan(ours) & np.isnan(theirs))))[0])
            pytest.fail(f"{what}: {signal} differs from row {k}: {ours[k]!r} != {theirs[k]!r}")
    assert batch.t.tobytes() == scalar.t.tobytes()


# -- the exact array functions -------------------------------------------------------------
def test_exact_functions_give_the_math_modules_bits():
    rng = np.random.default_rng(29)
    x = rng.normal(size=50_000) * 10.0 ** rng.integers(-8, 8, 50_000)
    y = rng.normal(size=50_000) * 10.0 ** rng.integers(-8, 8, 50_000)
    special = np.array([0.0, -0.0, math.pi, -math.pi, 3 * math.pi, -3 * math.pi, 2 * math.pi,
                        5e-324, 1e308, -1e308, math.inf, -math.inf, math.nan])
    angles = np.concatenate([x, special, np.arange(-40, 41) * math.pi])
    for ours, theirs in ((exact.wrap(angles), [wrap(a) if math.isfinite(a) else math.nan
                                              for a in angles]),
                         (exact.tanh(x), [math.tanh(a) for a in x]),
                         (exact.hypot(x, y), [math.hypot(a, b) for a, b in zip(x, y)])):
        assert ours.tobytes() == np.array(theirs).tobytes()


def test_the_acceptance_circle_is_decided_as_math_hypot_decides():
    """np.hypot decides far from the circle, math.hypot near it: the same booleans on
    points at, an ulp or two off and well off circles, Pythagorean triples, the specials."""
    from cosim.ensemble.control import _within

    rng = np.random.default_rng(18)
    radius = rng.uniform(1e-3, 1e3, 100_000)
    angle = rng.uniform(0.0, 2.0 * math.pi, radius.size)
    off = rng.choice([0.0, 1e-16, -1e-16, 3e-16, -3e-16, 1e-13, -1e-13, 1e-3, -1e-3], radius.size)
    dx, dy = radius * (1.0 + off) * np.cos(angle), radius * (1.0 + off) * np.sin(angle)
    triples = np.arange(1.0, 2001.0)
    specials = [(math.nan, 1.0, 1.0), (math.inf, math.nan, 1.0), (0.0, 0.0, 0.0),
                (-0.0, 5e-324, 5e-324), (1e308, 1e308, 1e308), (-math.inf, 0.0, 1e308)]
    dx = np.concatenate([dx, 3.0 * triples, [s[0] for s in specials]])
    dy = np.concatenate([dy, 4.0 * triples, [s[1] for s in specials]])
    radius = np.concatenate([radius, 5.0 * triples, [s[2] for s in specials]])
    expected = [math.hypot(a, b) <= r for a, b, r in zip(dx, dy, radius)]
    assert _within(dx, dy, radius).tolist() == expected


def test_remainder_ties_go_to_the_even_multiple():
    y = 2.0
    x = np.array([1.0, 3.0, -1.0, -3.0, 5.0, 7.0])
    assert exact.remainder(x, y).tolist() == [math.remainder(v, y) for v in x]


# -- the kernel against the in-process route -----------------------------------------------
def varied_members() -> list[dict]:
    """Seeds, headings across +-180 deg, gear, routes, acceptance radii and shaft speeds."""
    return [{"ship": {"wave_seed": 3, "psi0": 3.1}},
            {"ship": {"wave_seed": 4, "psi0": -3.1, "delta_rate_max": 0.1}},
            {"ship": {"wave_seed": 5, "n1": 9.0, "n2": 7.5},
             "guidance": {"waypoints": "0,0;8,0;8,8;0,8;0,0", "R_accept": 1.0}},
            {"ship": {"wave_seed": 6, "delta_max": 0.2, "psi_w": 1.0}},
            {"ship": {"Hs": 0.01, "T0": 1.1, "wave_seed": 7}}]


@pytest.mark.parametrize("scenario", [   # quick: a calm and a waves run, a PD and an SMC
    s if s in ("calm_pd", "waves_smc") else pytest.param(s, marks=pytest.mark.long)
    for s in COURSE_KEEPING])
def test_every_member_equals_its_in_process_run(scenario):
    system = scenarios.load(scenario)
    members = varied_members()
    if "smc" in scenario:
        members[0]["autopilot"] = {"equivalent_control": "tracking"}
        members[3]["autopilot"] = {"eta_h": 3.0, "phi_h": 0.05}
    else:
        members[0]["autopilot"] = {"Kp": 4.0, "Kd": 20.0}
    recordings = simulate_members(system, members, 120.0, SIGNALS)
    for i, (member, batch) in enumerate(zip(members, recordings)):
        assert batch.meta["backend"] == "batch", batch.meta["notes"]
        assert_same(batch, in_process(system, member, 120.0), f"{scenario} member {i}")
        assert batch.meta["parameters"] == in_process(system, member, 1.0).meta["parameters"]


@pytest.mark.parametrize("scenario", ("waves_pd", pytest.param("waves_smc",
                                                            marks=pytest.mark.long)))
def test_full_runs_of_the_paper_equal_in_process_runs(scenario):
    """400 s, where the chattering SMC turns any last bit into a visibly different run."""
    system = scenarios.load(scenario)
    members = [{"ship": {"wave_seed": seed}} for seed in (2010, 1, 2)]
    for member, batch in zip(members, simulate_members(system, members)):
        assert_same(batch, in_process(system, member, system.stop_time), str(member))


def test_members_of_different_seas_are_grouped_and_each_exact():
    system = scenarios.load("waves_pd")
    members = [{"ship": {"Hs": 0.0}}, {"ship": {"wave_components": 20, "wave_seed": 9}},
               {"ship": {"wave_seed": 9}}, {"ship": {"Hs": 0.0, "psi0": 1.0}}]
    for i, (member, batch) in enumerate(zip(members, simulate_members(system, members, 60.0))):
        assert batch.meta["backend"] == "batch"
        assert_same(batch, in_process(system, member, 60.0), f"member {i}")


# -- what the kernel does not run, and failures --------------------------------------------
def test_a_member_refused_at_configure_is_named_before_anything_runs():
    with pytest.raises(ValueError, match=r"member 1: .*Hs"):
        simulate_members(scenarios.load("waves_pd"), [{}, {"ship": {"Hs": -1.0}}], 10.0)


def test_an_smc_member_whose_reference_model_cuts_the_step_runs_alone_and_exact():
    system = scenarios.load("calm_smc")
    members = [{}, {"autopilot": {"omega_n": 3.0, "zeta": 2.0}}]
    batch = simulate_members(system, members, 20.0)
    assert [r.meta["backend"] for r in batch] == ["batch", "inprocess"]
    assert batch[1].meta["notes"][-1] == (
        "ran on the in-process route, not in the batch: autopilot.omega_n = 3.0 rad/s and "
        "zeta = 2.0 cut the 0.1 s step of the reference model (44) into RK4 sub-steps, which "
        "the batch kernel does not")
    for member, recording in zip(members, batch):
        assert_same(recording, in_process(system, member, 20.0), str(member))


def test_a_member_failing_its_initialisation_has_the_in_process_error():
    system = scenarios.load("waves_pd")
    members = [{"ship": {"wave_seed": 1}}, {"ship": {"Hs": 0.1, "T0": 0.3}},
               {"ship": {"wave_seed": 2}}]
    batch = simulate_members(system, members, 30.0)
    assert batch[1].error and "steepness" in batch[1].error
    assert batch[1].meta["backend"] == "inprocess"
    assert any("not in the batch" in note for note in batch[1].meta["notes"])
    for member, recording in zip(members, batch):
        assert_same(recording, in_process(system, member, 30.0), str(member))


def test_a_member_going_non_finite_runs_alone_and_leaves_the_others_bits(monkeypatch):
    """No valid setting found makes the scalar ship diverge (50 rev/s, 5 m/s, steep seas all
    run), so a NaN is planted in one member's lane: that member is re-run alone on the
    in-process route, the others' bits are those of a batch without the fault."""
    from cosim.ensemble import vessel

    system = scenarios.load("waves_smc")
    members = [{"ship": {"wave_seed": s}} for s in range(4)]
    clean = simulate_members(system, members, 40.0)
    step = vessel.VesselArrays.step

    def faulty(self, t, h, delta_c):
        step(self, t, h, delta_c)
        if abs(t - 20.0) < 1e-9:
            self.u[2] = math.nan
    monkeypatch.setattr(vessel.VesselArrays, "step", faulty)
    faulted = simulate_members(system, members, 40.0)
    assert [r.meta["backend"] for r in faulted] == ["batch", "batch", "inprocess", "batch"]
    assert any("failed in the batch kernel" in note for note in faulted[2].meta["notes"])
    for a, b in zip(clean, faulted):
        assert_same(b, a, "with a fault in member 2")


def test_a_system_the_kernel_does_not_cover_runs_in_process_with_a_note(tmp_path):
    from cosim.ensemble.reference import coverage

    assert coverage(scenarios.load("turning_circle")) is not None
    system = scenarios.load("calm_pd", autopilot=scenarios.SCENARIO_DIR.parent.parent
                            / "fmus" / "pd_autopilot_c.fmu")
    why = coverage(system)
    assert why is not None and "pd_autopilot_c" in why
    [recording] = simulate_members(system, [{}], 10.0)
    assert recording.meta["backend"] == "inprocess" and why in recording.meta["notes"][-1]


def test_signals_outside_the_loop_run_alone_and_unknown_ones_are_refused_by_name():
    alone, = simulate_members(scenarios.load("calm_pd"), [{}], 1.0, ["ship.X_w"])
    assert alone.meta["backend"] == "inprocess" and alone.columns == ["ship.X_w"]
    assert "the batch kernel records no ship.X_w" in alone.meta["notes"][-1]
    with pytest.raises(ValueError, match="signals ship.nope: the run records "):
        simulate_members(scenarios.load("calm_pd"), [{}], 1.0, ["ship.nope"])


# -- the self-test -------------------------------------------------------------------------
def test_the_selftest_passes_here_and_catches_a_different_rounding(monkeypatch):
    assert selftest() is None
    from cosim.ensemble import control
    from cosim.ensemble import route as module

    monkeypatch.setattr(control, "tanh",                # one last bit up: what np.tanh
                        lambda x: np.nextafter(exact.tanh(x), np.inf))   # does on 27 % here
    module.selftest.cache_clear()
    try:
        reason = module.selftest()
    finally:
        monkeypatch.undo()
        module.selftest.cache_clear()
    assert reason is not None and "smc" in reason and "differs" in reason


def test_a_refusing_selftest_sends_every_member_to_the_in_process_route(monkeypatch):
    from cosim.ensemble import route

    monkeypatch.setattr(route, "selftest", lambda: "numpy rounds differently here")
    [recording] = simulate_members(scenarios.load("calm_pd"), [{}], 5.0)
    assert recording.meta["backend"] == "inprocess"
    assert "numpy rounds differently here" in recording.meta["notes"][-1]


def cpu_variants() -> list:
    """Every variant of ``cosim.studies.cpu_variants``; all but numpy at its baseline (the
    farthest from this machine's dispatch) in the long suite only."""
    from cosim.studies.cpu_variants import VARIANTS

    return [pytest.param(name, marks=() if name == "numpy at its baseline" else pytest.mark.long)
            for name in VARIANTS]


@pytest.mark.timeout(150)
@pytest.mark.parametrize("variant", cpu_variants())
def test_the_selftest_passes_under_other_cpus_numpy_openblas_and_libm(variant):
    """numpy's dispatch, OpenBLAS's kernels and glibc's FMA variants as on other CPUs
    (``cosim.studies.cpu_variants``): the kernel computes as the scalar models in each."""
    import os
    import subprocess
    import sys

    from cosim.studies.cpu_variants import VARIANTS

    done = subprocess.run([sys.executable, "-c", "from cosim.ensemble import selftest; "
                           "print(selftest())"], env={**os.environ, **VARIANTS[variant]},
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "None", f"{variant}: {done.stdout}"
