"""Ensembles: the sweep file, the task, Dask execution, resuming, failures, outputs."""
from __future__ import annotations

import json
import math
import re
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from cosim import scenarios
from cosim.analysis.metrics import cost
from cosim.analysis.seastate import model_scale
from cosim.core.files import FolderLock
from cosim.core.master import Master
from cosim.core.ssd import write_ssd
from cosim.studies import campaign, sweep_task
from cosim.studies.cluster import NoWorkers, SweepError
from cosim.studies.merit import METRICS
from cosim.studies.sweep_spec import Spec
from cosim.studies.sweep_tables import write_comparison, write_tables
from helpers import command, reference_seconds

EXAMPLE = Path(__file__).resolve().parent.parent / "docs" / "sweeps" / "example.toml"


def write_spec(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return path


SMALL = """
name = "small"
stop_time = 20
[axes]
wave_seed = [1, 2]
sea_state = [2]
"ship.delta_rate_max" = [0.349]
[plots]
map = ["wave_seed", "ship.delta_rate_max"]
"""


def test_example_spec_expands_to_every_combination():
    spec = Spec.read(EXAMPLE)
    runs = spec.runs()
    assert len(runs) == 2 * 3 * 3 == len({r["run_id"] for r in runs})
    assert Spec.read(EXAMPLE).runs() == runs            # stable run ids
    # what its comment says: 18 combinations in 14 runs
    assert "18 combinations in\n# 14 runs" in EXAMPLE.read_text()
    assert len(spec.shared_runs()) == 14


def test_settings_map_axes_to_fmu_parameters(tmp_path):
    spec = Spec.read(write_spec(tmp_path, """
        [controllers]
        smc = { scenario = "waves_smc", set = { "autopilot.eta_h" = 5.0 } }
        [axes]
        sea_state = [4]
        route = ["0,0;10,0"]
        psi_w = [1.0]
        "autopilot.zeta" = [0.7]
    """))
    scenario, overrides = spec.settings(spec.runs()[0])
    Hs, T0 = model_scale(4)
    assert scenario == "waves_smc"
    assert overrides == {"autopilot": {"eta_h": 5.0, "zeta": 0.7},
                         "ship": {"Hs": Hs, "T0": T0, "psi_w": 1.0},
                         "guidance": {"waypoints": "0,0;10,0"}}
    assert Hs == pytest.approx(1.875 / 70) and T0 == pytest.approx(8.8 / 70 ** 0.5)


@pytest.mark.parametrize("text, fragment", [
    ("[axes]\nwind = [1]", "axis 'wind'"),
    ("[axes]\nsea_state = [9]", "WMO code"),
    ("[axes]\nHs = []", "non-empty"),
    ("[controllers]\npd = { scenario = 'nope' }", "scenario 'nope'"),
    ("[axes]\nHs = [0.0]\n[plots]\nmap = ['T0', 'Hs']", "'T0', which is not an axis"),
    ("name = ", "cannot read"),
    ("[axes]\nwave_seed = { start = 1, count = 'three' }", "axis 'wave_seed' = .*a range is"),
    ("stop_time = 'long'", "stop_time = 'long': give a number"),
    ("stop = 400", "unknown key stop"),
    ("[controllers]\npd = 3", "controller 'pd' = 3: give a scenario"),
    ("[plots]\nmap = 'Hs'", "\\[plots\\] map = 'Hs': give two different axes"),
])
def test_bad_spec_is_refused_by_name(tmp_path, text, fragment):
    with pytest.raises(ValueError, match=fragment):
        Spec.read(write_spec(tmp_path, text))


def test_a_run_id_changes_with_everything_that_changes_its_result(fmu_paths, tmp_path):
    base = '[controllers]\npd = { scenario = "%s" }\nsmc = { scenario = "waves_smc" }\n' \
           '[axes]\nwave_seed = [1]\n'
    def ids(text: str) -> dict[str, str]:
        return {r["controller"]: r["run_id"] for r in Spec.read(
            write_spec(tmp_path, text)).runs()}
    first = ids(base % "waves_pd")
    assert ids(base % "waves_pd") == first                              # stable
    assert set(ids("stop_time = 100\n" + base % "waves_pd").values()).isdisjoint(first.values())
    changed = ids(base.replace('"waves_smc" }', '"waves_smc", set = { "autopilot.eta_h" = 9.0 } }')
                  % "waves_pd")
    assert changed["pd"] == first["pd"] and changed["smc"] != first["smc"]
    system = scenarios.load("waves_pd")                   # the same scenario, one value changed
    system.components["autopilot"].parameters["Kd"] = 51.0
    write_ssd(system, tmp_path / "edited.ssd")
    assert ids(base % (tmp_path / "edited.ssd"))["pd"] != first["pd"]
    own = tmp_path / "mine.fmu"                          # an autopilot FMU: by content
    mine = '[controllers]\nmine = { autopilot = "mine.fmu" }\n[axes]\nwave_seed = [1]\n'
    own.write_bytes(fmu_paths["pd_autopilot"].read_bytes())
    before = ids(mine)
    own.write_bytes(fmu_paths["pid_autopilot"].read_bytes())
    assert ids(mine) != before


def test_task_equals_a_direct_run_and_reuses_its_fmus(fmu_paths, tmp_path):
    spec = Spec.read(write_spec(tmp_path, SMALL))
    first, again = spec.runs()[0], spec.runs()[0]
    row = campaign.run_locally(spec, first)
    master_before = dict(sweep_task._masters)
    assert campaign.run_locally(spec, again)["J"] == row["J"]        # after fmi2Reset, bit for bit
    assert dict(sweep_task._masters) == master_before              # same instances, reused
    master = Master(scenarios.load("waves_pd"),
                    overrides={"ship": {"wave_seed": 1, "Hs": model_scale(2)[0],
                                        "T0": model_scale(2)[1], "delta_rate_max": 0.349}})
    try:
        assert row["J"] == cost(master.run(20.0)).J
    finally:
        master.free()
    assert row["status"] == "ok" and set(METRICS) <= set(row)
    sweep_task.free_masters()


def test_an_in_process_sweep_notes_each_fmu_that_runs_through_fmi(c_autopilot, tmp_path):
    spec = Spec.read(write_spec(tmp_path, f'[controllers]\npd = "waves_pd"\n'
                                                f'c = "{c_autopilot}"\n[axes]\nwave_seed = [1]\n'))
    assert spec.backend_notes("fmi") == []
    assert spec.backend_notes("inprocess") == [
        "controller 'c': autopilot (pd_autopilot_c.fmu) runs through FMI, not in-process: it "
        "was not built with fmukit (it has no manifest)"]
    # a row says how its components ran, not only what was asked
    spec = Spec.read(write_spec(tmp_path, f'stop_time = 5\n[controllers]\npd = "waves_pd"\n'
                                                f'c = "{c_autopilot}"\n[axes]\nwave_seed = [1]\n'))
    rows = {r["controller"]: campaign.run_locally(spec, r, "inprocess") for r in spec.runs()}
    assert rows["pd"]["backend"] == "inprocess"
    assert rows["c"]["backend"] == "inprocess; autopilot: fmi, isolated"
    assert rows["c"]["J"] == rows["pd"]["J"]                 # the same PD law, in C
    sweep_task.free_masters()


def test_task_records_a_failed_run_with_its_message(fmu_paths, tmp_path):
    spec = Spec.read(write_spec(tmp_path, '[axes]\nHs = [0.1]\nT0 = [0.2]\n'))  # too steep
    row = campaign.run_locally(spec, spec.runs()[0])
    assert row["status"] == "failed" and "parameter Hs = 0.1 m with T0 = 0.2 s: steepness" in \
        row["error"]
    assert math.isnan(row["J"])
    sweep_task.free_masters()


@pytest.mark.timeout(180, method="thread")
def test_dask_sweep_writes_resumes_and_plots(fmu_paths, tmp_path, capsys, scheduler):
    spec = Spec.read(write_spec(tmp_path, SMALL))
    out = tmp_path / "out"
    out.mkdir()
    rows = campaign.execute(spec, out, scheduler, progress=False)
    assert [r["status"] for r in rows] == ["ok"] * 4
    journal = (out / "runs.jsonl").read_text().splitlines()
    assert len(journal) == 4
    # Resume: a failed row and a torn last line (a write cut by a kill) are run again;
    # nothing else is.
    failed = {**json.loads(journal[0]), "status": "failed", "error": "a worker was lost"}
    torn = journal[3][: len(journal[3]) // 2]
    (out / "runs.jsonl").write_text("\n".join([json.dumps(failed), *journal[1:3], torn]))
    # resumed in-process: the same rows, bit for bit (the backend is not part of a run's id)
    assert spec.backend_notes("inprocess") == []
    again = campaign.execute(spec, out, scheduler, progress=False, backend="inprocess")
    err = capsys.readouterr().err
    assert "is not a whole journal row" in err and "2 of 4 runs already done in" in err
    assert [r["J"] for r in again] == [r["J"] for r in rows]
    assert sorted(r["backend"] for r in again) == ["fmi", "fmi", "inprocess", "inprocess"]
    redone = [json.loads(line)["run_id"] for line in
              (out / "runs.jsonl").read_text().splitlines()[4:]]
    assert sorted(redone) == sorted(json.loads(journal[i])["run_id"] for i in (0, 3))
    written = write_tables(again, out, csv=True, spec=spec)
    table = pq.read_table(written[0])
    assert table.num_rows == 4 and {"controller", "wave_seed", "J", "status"} <= set(
        table.column_names)
    from cosim.studies.sweep_figures import save_figures
    assert all(p.stat().st_size > 5000 for p in save_figures(spec, again, out))
    (path,) = write_comparison(spec, again, out)
    header, rule, *settings = path.read_text().split("\n\n")[-1].splitlines()
    assert "smc wins" in header and len(settings) == 1          # one setting, two seeds
    J = {(r["controller"], r["wave_seed"]): r["J"] for r in again}
    wins = sum(J[("smc", s)] < J[("pd", s)] for s in (1, 2))
    assert f"| {wins}/2 |" in settings[0]


def test_a_journal_has_one_writer(fmu_paths, tmp_path):
    spec = Spec.read(write_spec(tmp_path, SMALL))
    with FolderLock(tmp_path):
        with pytest.raises(SweepError, match=f"output folder {tmp_path} is being written by "
                                             "another command"):
            campaign.execute(spec, tmp_path, workers=1, progress=False)


def test_a_journal_is_a_file_of_its_own_and_a_bad_line_is_skipped(tmp_path, capsys):
    """Issue 38: an undecodable line stopped a resume; a symbolic link was followed."""
    journal = tmp_path / "runs.jsonl"
    journal.write_bytes(b'{"run_id": "a", "status": "ok"}\n\xff\xfe not UTF-8\n'
                        b'{"run_id": "b", "status": "failed"}\n')
    assert sorted(campaign.read_rows(journal)) == ["a", "b"]
    assert f"warning: {journal}:2 is not a whole journal row" in capsys.readouterr().err
    elsewhere = tmp_path / "elsewhere.jsonl"
    elsewhere.write_text("")
    (tmp_path / "linked").mkdir()
    (tmp_path / "linked" / "runs.jsonl").symlink_to(elsewhere)
    with pytest.raises(SweepError, match="runs.jsonl is a symbolic link; remove it"):
        campaign.Journal(tmp_path / "linked" / "runs.jsonl")
    assert elsewhere.read_text() == ""


def test_a_spec_nested_too_deeply_is_refused_by_name(tmp_path):
    spec = tmp_path / "deep.toml"
    spec.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(ValueError, match="deep.toml: its tables or arrays are nested too "
                                         "deeply"):
        Spec.read(spec)


@pytest.mark.timeout(600, method="thread")
def test_a_worker_killed_on_every_retry_is_recorded_as_failed(fmu_paths, tmp_path):
    """The nannies restart the workers each time. Under load, a nanny was seen to close
    instead, with the restarted worker (distributed 2026.8): with one worker, the sweep then
    stopped for want of any (NoWorkers, its rows kept); with two, the other goes on."""
    from sweep_faults import killing_task
    spec = Spec.read(write_spec(tmp_path, 'stop_time = 5\n[axes]\nwave_seed = [1, 2]\n'))
    rows = campaign.execute(spec, tmp_path, workers=2, progress=False, task=killing_task,
                            no_worker_timeout=120)
    by_seed = {(r["controller"], r["wave_seed"]): r for r in rows}
    assert by_seed[("pd", 1)]["status"] == "ok"
    assert by_seed[("pd", 2)]["status"] == "failed"
    assert "KilledWorker" in by_seed[("pd", 2)]["error"]


@pytest.mark.timeout(300, method="thread")
def test_a_sweep_left_without_a_worker_stops_keeps_its_rows_and_says_why(
        fmu_paths, tmp_path, capsys, monkeypatch):
    """The only worker is killed and not replaced (its nanny told not to restart it, as one
    that fails to): the command stops after --no-worker-timeout instead of waiting for ever."""
    from sweep_faults import killing_task_after_one_row

    from cosim import sweep as command
    from cosim.studies.cluster import local_cluster

    spec = write_spec(tmp_path, 'name = "orphan"\nstop_time = 5\n[axes]\nwave_seed = [1, 2]\n')
    out = tmp_path / "out" / "orphan"
    monkeypatch.setattr(campaign, "run_one", killing_task_after_one_row)
    monkeypatch.setenv("SWEEP_FAULTS_JOURNAL", str(out / "runs.jsonl"))
    cluster = local_cluster(1)
    try:
        for nanny in cluster.workers.values():
            nanny.close_gracefully()                        # no restart when its worker dies
        started = time.monotonic()
        status = command.main([str(spec), "--scheduler", cluster.scheduler_address, "--out",
                               str(tmp_path / "out"), "--no-worker-timeout", "2",
                               "--no-progress"])
        took = time.monotonic() - started
    finally:
        cluster.close()
    err = capsys.readouterr().err
    assert status == NoWorkers.exit_status == 3, err
    assert re.search(r"no worker in the cluster for 2 s \(the last one left by [-\d]+ [:\d]+\); "
                     r"the sweep stopped: 1 of 4 runs done, kept in \S+/runs.jsonl, "
                     r"\S+/results.parquet, .*; this command resumes the sweep: \S+ -m "
                     r"cosim.sweep \S+/spec.toml --scheduler tcp://\S+ --out ", err), err
    journal = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines()]
    assert [r["status"] for r in journal] == ["ok"]
    assert pq.read_table(out / "results.parquet").num_rows == 1
    assert took < 2 + 10 * reference_seconds(tmp_path / "reference")   # a run, 2 s, closing


@pytest.mark.timeout(30, method="thread")
def test_a_sweep_on_a_cluster_that_never_had_a_worker_stops_too(fmu_paths, tmp_path, capsys):
    from cosim import sweep as command
    from cosim.studies.cluster import local_cluster

    path = write_spec(tmp_path, 'stop_time = 5\n[axes]\nwave_seed = [1]\n')
    with pytest.raises(SystemExit):
        command.main([str(path), "--no-worker-timeout", "0"])
    assert "expected a positive number of seconds, got '0'" in capsys.readouterr().err
    spec = Spec.read(path)
    cluster = local_cluster(0)
    try:
        with pytest.raises(NoWorkers, match=r"no worker in the cluster for 0.5 s \(none "
                                                  r"has joined since [-\d]+ [:\d]+\)"):
            campaign.execute(spec, tmp_path, scheduler=cluster.scheduler_address, progress=False,
                          no_worker_timeout=0.5)
    finally:
        cluster.close()
    assert campaign.completed(spec, tmp_path) == []


@pytest.mark.timeout(300, method="thread")
def test_two_sweeps_on_one_cluster_both_finish_with_every_row(fmu_paths, tmp_path, scheduler):
    """Each sweep frees only its own FMUs: the first to end must not free the other's."""
    from concurrent.futures import ThreadPoolExecutor

    for name in ("short", "long"):
        (tmp_path / name).mkdir()
    specs = [Spec.read(write_spec(tmp_path / name, text)) for name, text in (
        ("short", 'name = "short"\nstop_time = 5\n[axes]\nwave_seed = [1, 2]\n'),
        ("long", 'name = "long"\nstop_time = 60\n[axes]\nwave_seed = [1, 2, 3]\n'))]
    with ThreadPoolExecutor(2) as pool:
        running = [pool.submit(campaign.execute, spec, tmp_path / spec.name,
                               scheduler=scheduler, progress=False) for spec in specs]
        done = [future.result(timeout=240) for future in running]   # not stuck
    assert [len(rows) for rows in done] == [4, 6]
    assert all(r["status"] == "ok" for rows in done for r in rows), done


def test_when_every_run_fails_the_summary_still_names_each_failure(fmu_paths, tmp_path,
                                                                  scheduler):
    from cosim import sweep as sweep_command

    # each value in its range, the two together against the ship's rule: the FMU's refusal
    spec = write_spec(tmp_path, 'name = "bad"\nstop_time = 5\n[axes]\nHs = [0.1]\nT0 = [0.2]\n')
    child = command(sweep_command.main, str(spec), "--scheduler", scheduler, "--out",
                    str(tmp_path / "out"), "--no-progress")
    assert child.returncode == 1, child.stderr
    assert "bad: 2 runs, 0 ok, 2 failed" in child.stdout
    for controller in ("pd", "smc"):
        assert (f"failed {controller} (Hs = 0.1, T0 = 0.2): FMU 'ship': exitInitializationMode at "
                "t = 0 s returned OK but logged an error / [error] ship: exitInitializationMode "
                "at t = 0.0: parameter Hs = 0.1 m with T0 = 0.2 s: steepness") in child.stdout, \
            child.stdout
    assert "no run succeeded: no figures drawn" in child.stderr
    assert (tmp_path / "out" / "bad" / "results.parquet").exists()


@pytest.mark.timeout(300)
def test_a_finished_sweep_removes_what_an_earlier_spec_of_its_name_wrote(fmu_paths, tmp_path,
                                                                        capsys, scheduler):
    """Run a spec with pd and smc, then one of the same name with pd alone: the ratio map
    and comparison.md of the first would otherwise stand beside the second's tables."""
    from cosim import sweep as command
    both = (SMALL + '[controllers]\npd = { scenario = "waves_pd" }\n'
            'smc = { scenario = "waves_smc" }\n')
    alone = SMALL.replace('map = ["wave_seed", "ship.delta_rate_max"]', "") + \
        '[controllers]\npd = { scenario = "waves_pd" }\n'
    out = tmp_path / "out"
    assert command.main([str(write_spec(tmp_path, both)), "--out", str(out), "--scheduler",
                         scheduler, "--no-progress"]) == 0
    assert {"comparison.md", "J_smc_over_pd.png"} <= {p.name for p in (out / "small").iterdir()}
    # a clean finish leaves no lock and no hidden file
    assert [p.name for p in (out / "small").iterdir()
            if p.name.startswith(".") or p.suffix == ".lock"] == []
    (out / "small" / "notes.txt").write_text("the user's")
    assert command.main([str(write_spec(tmp_path, alone)), "--out", str(out), "--scheduler",
                         scheduler, "--no-progress"]) == 0
    left = {p.name for p in (out / "small").iterdir()}
    assert "comparison.md" not in left and "J_smc_over_pd.png" not in left
    assert {"results.parquet", "results.json", "J_distribution.png", "notes.txt"} <= left
