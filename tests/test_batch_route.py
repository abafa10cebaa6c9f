"""The batch backend of sweeps, scorecards and cosim.simulate_many: its rows and recordings are
the in-process route's, every column but backend, seconds and sim_seconds; its fallbacks.

The kernel itself (every signal against the scalar models) is pinned by test_ensemble*.py.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import re
import time
from pathlib import Path

import numpy as np
import pytest

import cosim
from cosim import simulate_many
from cosim.core.recording import TooManyRows
from cosim.studies import campaign, sweep_task
from cosim.studies.campaign import plan
from cosim.studies.sweep_spec import Spec

from helpers import fmu_variant

EXEMPT = {"backend", "seconds", "sim_seconds"}
"""The columns a run's row may differ in between the routes: how and how fast it ran."""

TURNING = "0,0;0,30"
"""A route that turns the ship at once (it starts heading north, along x)."""

MIXED = f"""
name = "mixed"
stop_time = 40
[controllers]
pd = "waves_pd"
soft = {{ scenario = "waves_pd", set = {{ "autopilot.Kd" = 30.0 }} }}
smc = "waves_smc"
calm = "calm_pd"
pid = "calm_pid"
[axes]
route = ["0,0;30,0;60,25;90,25", "{TURNING}"]
"""
"""Ten runs: PD at two gains and SMC in waves, PD and PID in calm water, on two routes."""


def write_spec(folder: Path, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "spec.toml").write_text(text)
    return folder / "spec.toml"


def same(a, b) -> bool:
    return a == b or (isinstance(a, float) and isinstance(b, float)
                      and math.isnan(a) and math.isnan(b))


def assert_same_row(ours: dict, theirs: dict) -> None:
    """Every column of two rows of one run equal (NaN to NaN) but ``EXEMPT``."""
    assert ours.keys() == theirs.keys()
    differ = [k for k in ours.keys() - EXEMPT if not same(ours[k], theirs[k])]
    assert not differ, {k: (ours[k], theirs[k]) for k in differ}


def journal(out: Path) -> dict[str, dict]:
    return {row["run_id"]: row for row in map(json.loads,
                                              (out / "runs.jsonl").read_text().splitlines())}


@pytest.fixture(scope="module")
def mixed(fmu_paths, scheduler, tmp_path_factory) -> tuple[Spec, dict, dict]:
    """MIXED run on both routes: (its spec, the in-process journal, the batch journal)."""
    folder = tmp_path_factory.mktemp("mixed")
    spec = Spec.read(write_spec(folder, MIXED))
    journals = {}
    for backend in ("inprocess", "batch"):
        (folder / backend).mkdir()
        rows = campaign.execute(spec, folder / backend, scheduler=scheduler,
                             progress=False, backend=backend)
        assert [r["status"] for r in rows] == ["ok"] * 10
        journals[backend] = journal(folder / backend)
    return spec, journals["inprocess"], journals["batch"]


@pytest.mark.timeout(240, method="thread")
def test_a_batch_sweep_journals_the_in_process_rows(mixed):
    spec, inprocess, batch = mixed
    assert spec.batch_coverage == dict.fromkeys(spec.controllers)       # all covered
    assert spec.backend_notes("batch") == []
    assert inprocess.keys() == batch.keys() == {r["run_id"] for r in spec.runs()}
    for run_id, row in batch.items():
        assert_same_row(row, inprocess[run_id])
        assert row["backend"] == "batch"
        assert row["sim_seconds"] > 0 and row["seconds"] >= row["sim_seconds"]
    turning = {r["controller"]: r["J"] for r in batch.values() if r["route"] == TURNING}
    assert len(set(turning.values())) == 4 and min(turning.values()) > 1.0
    assert turning["pid"] == turning["calm"]        # its integrator is off this far off course


@pytest.mark.timeout(240, method="thread")
@pytest.mark.parametrize("first, then", [("inprocess", "batch"), ("batch", "inprocess")])
def test_a_sweep_resumes_on_the_other_backend(mixed, scheduler, tmp_path, first, then):
    spec, *full = mixed
    done = dict(zip(("inprocess", "batch"), full))[first]
    kept = list(done.values())[:5]
    (tmp_path / "runs.jsonl").write_text("".join(json.dumps(r) + "\n" for r in kept))
    rows = campaign.execute(spec, tmp_path, scheduler=scheduler, progress=False,
                         backend=then)
    assert len(rows) == 10
    resumed = journal(tmp_path)
    assert [resumed[r["run_id"]]["backend"] for r in kept] == [first] * 5     # not run again
    assert sorted(r["backend"] for r in resumed.values()) == sorted([first] * 5 + [then] * 5)
    reference = full[0]                                                   # in-process
    for run_id, row in resumed.items():
        assert_same_row(row, reference[run_id])


def test_batch_sizes_keep_every_worker_busy_within_the_memory_of_their_recordings(tmp_path):
    from dataclasses import replace

    from cosim.studies.campaign import BATCH_MEMORY, MAX_BATCH, batch_counts, batch_limit

    spec = Spec.read(write_spec(tmp_path, 'name = "b"\n[axes]\n'
                                      'wave_seed = { start = 1, count = 2 }\n'))
    long = spec.job(spec.runs()[0], "t", "inprocess")              # the scenario's 400 s
    short = replace(long, stop_time=20.0)
    assert batch_limit(long) == BATCH_MEMORY // (6 * 8 * 4001) == 698
    assert batch_limit(short) == MAX_BATCH

    def sizes(n, workers, size=None, job=long):
        return [len(b) for b in plan(spec, [job] * n, workers, size)[0]]
    assert sizes(1000, 2) == [500, 500]
    assert sizes(3000, 2) == [600] * 5                     # at most 698 runs of 400 s
    assert sizes(3000, 2, job=short) == [1000] * 3         # at most MAX_BATCH
    assert sizes(100, 2) == [50, 50]
    assert sizes(40, 2) == [40]                            # a few dozen each
    assert sizes(10, 4) == [10]
    assert sizes(20, 2, size=7) == [7, 6, 7]
    jobs = [replace(long, run={**long.run, "run_id": str(i)}) for i in range(23)]
    assert sum(plan(spec, jobs, 3, size=5)[0], []) == jobs  # in order
    # A sweep of several systems: in calm water as few batches as keep the workers busy,
    # in all; in waves each system shared among the workers, down to WAVES_SHARE runs.
    calm = replace(long, overrides={**long.overrides, "ship": {**long.overrides.get("ship", {}),
                                                               "Hs": 0.0}})
    assert batch_counts([[calm] * 512, [calm] * 512], 2) == [1, 1]
    assert batch_counts([[long] * 512, [long] * 512], 2) == [2, 2]
    assert batch_counts([[calm] * 600, [calm] * 100], 4) == [3, 1]
    assert batch_counts([[long] * 600, [long] * 100], 4) == [4, 1]
    assert batch_counts([[long] * 255, [long] * 256], 2) == [1, 2]
    assert batch_counts([[calm] * 40, [long] * 10], 4) == [1, 1]
    assert batch_counts([[long] * 800, [short] * 3000], 2) == [2, 3]


def test_a_batch_has_the_time_limits_of_its_runs_together():
    from cosim.core.watchdog import Limits

    assert sweep_task.batch_limits(Limits(2.0, 10.0, 3.0), 5) == Limits(10.0, 50.0, 3.0)
    assert sweep_task.batch_limits(Limits(None, None), 7) == Limits(None, None)


@pytest.mark.timeout(240, method="thread")
def test_a_foreign_autopilot_runs_alone_in_process_with_a_note(fmu_paths, scheduler, tmp_path,
                                                              capsys):
    """Our PD without its manifest is an FMU not built with fmukit: not the kernel's."""
    from cosim import sweep as command

    foreign = fmu_variant(fmu_paths["pd_autopilot"], tmp_path / "foreign.fmu",
                          drop=("resources/fmukit_manifest.json",))
    spec_file = write_spec(tmp_path, f'name = "foreign"\nstop_time = 20\n[controllers]\n'
                                     f'pd = "waves_pd"\nmine = "{foreign}"\n'
                                     '[axes]\nwave_seed = [1, 2]\n')
    spec = Spec.read(spec_file)
    why = ("autopilot (foreign.fmu) runs through FMI, not in-process: it was not built with "
           "fmukit (it has no manifest)")
    assert spec.batch_coverage == {"pd": None, "mine": why}
    assert spec.backend_notes("batch") == [
        f"controller 'mine' runs on the in-process route, one run per task, not in batches: "
        f"{why}"]
    assert spec.backend_notes("inprocess") == [f"controller 'mine': {why}"]
    plan_batches, alone = plan(spec, [spec.job(r, "t", "inprocess") for r in spec.runs()], 2)
    assert [[j.run["controller"] for j in b] for b in plan_batches] == [["pd", "pd"]]
    assert [j.run["controller"] for j in alone] == ["mine", "mine"]
    assert command.main([str(spec_file), "--backend", "batch", "--scheduler",
                         scheduler, "--out", str(tmp_path / "out"),
                         "--no-progress"]) == 0
    assert f"note: controller 'mine' runs on the in-process route, one run per task, not in " \
           f"batches: {why}" in capsys.readouterr().err
    rows = journal(tmp_path / "out" / "foreign")
    by = {(r["controller"], r["wave_seed"]): r for r in rows.values()}
    assert {by["pd", s]["backend"] for s in (1, 2)} == {"batch"}
    assert {by["mine", s]["backend"] for s in (1, 2)} == {"inprocess; autopilot: fmi, isolated"}
    for seed in (1, 2):
        assert by["mine", seed]["J"] == by["pd", seed]["J"]            # the same PD law


def test_batch_size_is_refused_without_the_batch_backend(capsys):
    from cosim import sweep as command

    with pytest.raises(SystemExit):
        command.main(["spec.toml", "--batch-size", "10"])
    assert "--batch-size sizes the batches of --backend batch, not of --backend fmi" in \
        capsys.readouterr().err


# -- one batch in this process: its members' failures and its own --------------------------
@pytest.fixture
def members(fmu_paths, tmp_path) -> tuple[list[sweep_task.Job], dict[str, bytes]]:
    """Six runs of waves_pd, 30 s: four seeds on two routes (the turning one also in calm
    water), one whose sea its ship refuses at initialisation (too steep), and one whose
    settings Master.configure refuses (Hs < 0: the spec would refuse it, a job need not)."""
    spec = Spec.read(write_spec(tmp_path, f"""
        stop_time = 30
        [controllers]
        pd = "waves_pd"
        [axes]
        route = ["0,0;30,0;60,25;90,25", "{TURNING}"]
        wave_seed = [1, 2]
        """))
    jobs = [spec.job(run, "local", "inprocess") for run in spec.runs()]
    steep = {**jobs[0].run, "run_id": "steep"}
    refused = {**jobs[0].run, "run_id": "refused"}
    jobs += [dataclasses.replace(jobs[0], run=steep, overrides={
                 **jobs[0].overrides, "ship": {"Hs": 0.1, "T0": 0.2, "wave_seed": 1}}),
             dataclasses.replace(jobs[0], run=refused, overrides={
                 **jobs[0].overrides, "ship": {"Hs": -1.0}})]
    jobs.insert(2, jobs.pop())                      # the refused one among the others
    blobs = {sha: path.read_bytes() for sha, path in spec.files().items()}
    yield jobs, blobs
    sweep_task.free_masters()


def test_members_that_fail_are_the_in_process_failures_and_change_no_other(members,
                                                                         monkeypatch):
    """A member refused by Master.configure, one refused at initialisation and two that
    fail in the kernel (its yaw-rate bound made tiny here, so that the turning ones pass it)
    get the in-process route's rows; every other member's row is the in-process one too."""
    from cosim.ensemble import route

    jobs, blobs = members
    alone = [sweep_task.run_one(job, blobs) for job in jobs]
    assert sweep_task.batch_refusal() is None       # the self-test passed (once per process)
    monkeypatch.setattr(route, "R_MAX", 0.01)
    together = sweep_task.run_batch(jobs, blobs)
    assert [r["run_id"] for r in together] == [j.run["run_id"] for j in jobs]
    for ours, theirs in zip(together, alone, strict=True):
        assert_same_row(ours, theirs)
    by = {(r["run_id"] if r["run_id"] in ("steep", "refused") else r["route"], r["wave_seed"]): r
          for r in together}
    assert "ship.Hs = -1.0 is outside its declared range" in by["refused", 1]["error"]
    assert "steepness" in by["steep", 1]["error"]
    assert sorted(r["status"] for r in together) == ["failed"] * 2 + ["ok"] * 4
    assert {by["0,0;30,0;60,25;90,25", s]["backend"] for s in (1, 2)} == {"batch"}
    assert {by[TURNING, s]["backend"] for s in (1, 2)} == {
        "inprocess (ran on the in-process route, not in the batch: it failed in the batch "
        "kernel, and ran alone to say why)"}
    assert by["steep", 1]["backend"] == ("inprocess (ran on the in-process route, not in the "
                                          "batch: its initialisation failed)")
    assert by["refused", 1]["backend"] == "inprocess"


def test_a_batch_that_fails_as_a_whole_runs_each_member_alone(members, monkeypatch):
    import cosim.ensemble

    jobs, blobs = members
    alone = [sweep_task.run_one(job, blobs) for job in jobs]

    def broken(*args, **kwargs):
        raise RuntimeError("the kernel broke")
    monkeypatch.setattr(cosim.ensemble, "simulate_members", broken)
    together = sweep_task.run_batch(jobs, blobs)
    for ours, theirs in zip(together, alone, strict=True):
        assert_same_row(ours, theirs)
        assert ours["backend"] == (f"{theirs['backend']} (not in a batch: the batch failed, "
                                   "RuntimeError: the kernel broke; run alone)")


def test_a_batch_past_its_time_limit_in_the_kernel_stops_and_runs_each_member_alone(
        members, monkeypatch):
    """The kernel asks the watchdog at every step: past the batch's run limit (its runs'
    limits together) it stops at the next step, and the runs run alone within theirs. The
    limits are four times what a run takes here now, so that a busy machine meets them."""
    from cosim.core.watchdog import Limits
    from cosim.ensemble.vessel import VesselArrays

    jobs, blobs = members
    started = time.monotonic()
    sweep_task.run_one(jobs[0], blobs)
    limit = max(0.25, math.ceil(80 * (time.monotonic() - started)) / 20)     # 0.05 s steps
    jobs = [dataclasses.replace(job, limits=Limits(run=limit)) for job in jobs[:2]]
    alone = [sweep_task.run_one(job, blobs) for job in jobs]
    assert sweep_task.batch_refusal() is None       # the self-test, before the kernel is slowed
    step, steps = VesselArrays.step, []

    def slow(self, *args):                  # 300 steps: three times the batch's limit
        steps.append(time.monotonic())
        time.sleep(6 * limit / 300)
        return step(self, *args)
    monkeypatch.setattr(VesselArrays, "step", slow)
    started = time.monotonic()
    together = sweep_task.run_batch(jobs, blobs)
    assert len(steps) < 300
    late = [t for t in steps if t - started > 2 * limit]
    assert len(late) <= 2                           # stopped at the step after its limit
    for ours, theirs in zip(together, alone, strict=True):
        assert_same_row(ours, theirs)
        assert ours["backend"] == (f"{theirs['backend']} (not in a batch: the batch failed, "
                                   f"the run did not end within its time limit of "
                                   f"{2 * limit:g} s; run alone)")


# -- a batch whose worker dies ---------------------------------------------------------------
def killing_batch(jobs, blobs):
    """A batch of more than one run ends its worker; runs alone run."""
    if len(jobs) > 1:
        os._exit(3)
    return sweep_task.run_batch(jobs, blobs)


@pytest.mark.timeout(240, method="thread")
def test_a_batch_whose_worker_dies_on_every_retry_runs_each_run_alone(fmu_paths, tmp_path):
    """On a cluster of its own: the session's workers are not killed."""
    spec = Spec.read(write_spec(tmp_path, "stop_time = 5\n[controllers]\n"
                                                'pd = "waves_pd"\n[axes]\nwave_seed = [1, 2]\n'))
    rows = campaign.execute(spec, tmp_path, workers=2, progress=False, backend="batch",
                            batch_task=killing_batch, no_worker_timeout=60)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    for row in rows:
        assert row["backend"].startswith("inprocess (not in a batch: its batch's worker died, "
                                         "KilledWorker: ")
        assert_same_row(row, {**campaign.run_locally(spec, row, "inprocess"),
                              "ran_as": row["ran_as"], "command": row["command"]})
    sweep_task.free_masters()


# -- cosim.simulate_many ---------------------------------------------------------------------
def test_simulate_many_gives_the_in_process_recordings(fmu_paths):
    sets = [{"ship.wave_seed": 1}, {"ship.wave_seed": 2, "guidance.waypoints": TURNING},
            {"ship.Hs": 0.1, "ship.T0": 0.2}, {"autopilot.Kd": 30.0}]
    with pytest.warns(UserWarning, match="ran on the in-process route, not in the batch: its "
                                         "initialisation failed"):
        batch = cosim.simulate_many("waves_pd", sets, stop_time=30)
    inprocess = cosim.simulate_many("waves_pd", sets, stop_time=30, backend="inprocess")
    assert [r.meta["backend"] for r in batch] == ["batch", "batch", "inprocess", "batch"]
    from cosim.ensemble.reference import SIGNALS
    for ours, theirs in zip(batch, inprocess, strict=True):
        assert ours.columns == list(SIGNALS) and set(SIGNALS) < set(theirs.columns)
        assert ours.error == theirs.error and ours.rows == theirs.rows
        np.testing.assert_array_equal(ours.t, theirs.t)
        for column in ours.columns:
            np.testing.assert_array_equal(ours[column], theirs[column])
            assert ours.units[column] == theirs.units[column]
    assert batch[2].error and "steepness" in batch[2].error            # failed, not raised
    assert len({r["ship.psi"][-1] for r in batch if not r.error}) == 3
    one = cosim.simulate("waves_pd", set=sets[1], stop_time=30)       # the single-run API
    np.testing.assert_array_equal(one["ship.psi"], batch[1]["ship.psi"])
    narrow = cosim.simulate_many("waves_pd", sets[:1], stop_time=30, backend="inprocess",
                                 signals=["ship.x", "ship.y"])
    assert narrow[0].columns == ["ship.x", "ship.y"]
    np.testing.assert_array_equal(narrow[0]["ship.y"], batch[0]["ship.y"])


@pytest.mark.parametrize("backend", ["batch", "inprocess"])
def test_simulate_many_refuses_bad_settings_naming_the_member(fmu_paths, backend):
    with pytest.raises(ValueError, match=r"member 1: ship.Hs = -1.0 is outside its declared "
                                         r"range"):
        cosim.simulate_many("calm_pd", [{}, {"ship.Hs": -1.0}], stop_time=10, backend=backend)
    with pytest.raises(ValueError, match=r"member 0: set: 'Hs' is not 'component.variable'"):
        cosim.simulate_many("calm_pd", [{"Hs": 0.01}], backend=backend)
    with pytest.raises(ValueError, match="backend must be fmi, inprocess or batch, got 'gpu'"):
        cosim.simulate_many("calm_pd", [{}], backend="gpu")


def test_the_batch_route_refuses_what_in_process_refuses_in_the_same_words():
    """Issue 38: a batch of a billion seconds tried to allocate 745 GiB; a batch sweep whose
    every run runs alone (a user's FMU) ended in 'max() arg is an empty sequence'."""
    said = {}
    for backend in ("inprocess", "batch"):
        with pytest.raises(TooManyRows) as refused:
            simulate_many("calm_pd", [{}], stop_time=1e9, backend=backend)
        said[backend] = re.sub(r"\d[\d,.]*", "N", str(refused.value))
    assert said["batch"] == said["inprocess"]
    assert campaign.batch_counts([], workers=2) == []


def _outcome(scenario: str, backend: str, **kwargs) -> str | list:
    try:
        return cosim.simulate_many(scenario, backend=backend, **{"stop_time": 3, **kwargs})
    except (ValueError, TypeError) as refused:
        return f"{type(refused).__name__}: {refused}"


@pytest.mark.filterwarnings("ignore:ran on the in-process route")
@pytest.mark.parametrize("scenario, kwargs", [
    ("calm_pd", {"sets": [{}], "stop_time": 0.15}),
    ("calm_pd", {"sets": [{"ship.wave_seed": 1.5}]}),
    ("calm_pd", {"sets": [{"guidance.waypoints": "garbage"}]}),
    ("calm_pd", {"sets": [{"ship.psi0": "40deg"}, {"ship.psi0": "-179deg"}]}),
    ("calm_pd", {"sets": [{}], "signals": ["ship.nope"]}),
    ("calm_pd", {"sets": [{}], "signals": []}),
    ("calm_pd", {"sets": [{}], "signals": ["ship.X_w", "ship.psi"]}),   # alone: not in kernel
    ("zigzag_10_10", {"sets": [{}, {"ship.delta_rate_max": 0.1}]}),   # alone: every signal
])
def test_batch_takes_and_refuses_what_in_process_does(fmu_paths, scenario, kwargs):
    """Issue 38: the batch route crashed on no signals, refused a signal the run records and
    a manoeuvre's default signals, and named the signals it lacks in words of its own."""
    batch, inprocess = (_outcome(scenario, b, **kwargs) for b in ("batch", "inprocess"))
    if isinstance(inprocess, str):
        assert batch == inprocess
        return
    assert not isinstance(batch, str), batch
    for ours, theirs in zip(batch, inprocess, strict=True):
        assert ours.error == theirs.error and set(ours.columns) <= set(theirs.columns)
        np.testing.assert_array_equal(ours.t, theirs.t)
        for column in ours.columns:
            np.testing.assert_array_equal(ours[column], theirs[column])
    if scenario == "zigzag_10_10":
        assert batch[0].columns == inprocess[0].columns
