"""A real Dask cluster: a scheduler and two workers as separate processes, the project
installed from a wheel into their own environment (no checkout on their path); a sweep
with a user's autopilot FMU; one worker killed mid-sweep.

Every wait has a limit: the child processes' (``timeout``), the sweep's thread (``join``),
and the test's own (pytest-timeout's signal method, so that the fixture still kills the
cluster, whose processes are in sessions of their own and would outlive pytest)."""
from __future__ import annotations

import os
import signal
import shutil
import subprocess
import sys
import sysconfig
import threading
import time
import venv
from pathlib import Path

import pytest

from cosim.studies import campaign
from cosim.studies.cluster import SweepError, check_workers
from cosim.studies.sweep_spec import Spec
from cosim.studies.sweep_task import run_one
from fmubuild.project import ROOT

RUNS = 12


@pytest.fixture(scope="module")
def wheel_python(tmp_path_factory) -> Path:
    """A Python whose environment has the project from a wheel, and its dependencies."""
    root = tmp_path_factory.mktemp("wheel_env")
    # From a copy: setuptools builds in the source's build/ and keeps there, in every later
    # wheel, the modules a change has since deleted.
    source = shutil.copytree(ROOT, root / "source", ignore=shutil.ignore_patterns(
        ".git", ".venv", "build", "fmus", "results", "tests", "docs", "__pycache__",
        "*.egg-info"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w",
                    str(root / "dist"), str(source)], check=True, capture_output=True,
                   timeout=300)
    venv.create(root / "env", with_pip=False)
    python = root / "env" / "bin" / "python"
    site = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()"
                                "['purelib'])"], capture_output=True, text=True,
                               check=True, timeout=60).stdout.strip())
    # The dependencies from this environment: a plain path, so its .pth files (this
    # project's editable install among them) are not run.
    (site / "dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    wheel = next((root / "dist").glob("*.whl"))
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
                    str(site), str(wheel)], check=True, capture_output=True, timeout=300)
    return python


@pytest.fixture
def cluster(wheel_python, tmp_path):
    """(scheduler address, worker processes), all started in an empty folder."""
    home = tmp_path / "cluster"
    home.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION"] = "1.0"
    scheduler_file = home / "scheduler.json"
    processes = [subprocess.Popen([str(wheel_python), "-m", "dask", "scheduler", "--host",
                                   "127.0.0.1", "--port", "0", "--no-dashboard",
                                   "--scheduler-file", str(scheduler_file)], cwd=home, env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                  start_new_session=True)]
    deadline = time.monotonic() + 60
    while not scheduler_file.exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    if not scheduler_file.exists():
        os.killpg(processes[0].pid, signal.SIGKILL)
        processes[0].wait(timeout=10)
        pytest.fail("the Dask scheduler wrote no scheduler file within 60 s")
    for _ in range(2):
        processes.append(subprocess.Popen(
            [str(wheel_python), "-m", "dask", "worker", "--scheduler-file", str(scheduler_file),
             "--nthreads", "1", "--no-dashboard"], cwd=home, env=env,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True))
    yield scheduler_file, processes
    for process in processes:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait(timeout=10)


@pytest.mark.long      # the quick suite runs sweeps on local clusters (test_sweep.py)
@pytest.mark.timeout(300, method="signal")
def test_a_wheel_cluster_runs_a_sweep_and_loses_only_the_runs_in_flight(
        fmu_paths, cluster, tmp_path):
    from dask.distributed import Client

    scheduler_file, processes = cluster
    (tmp_path / "mine.fmu").write_bytes(fmu_paths["pid_autopilot"].read_bytes())
    spec_path = tmp_path / "spec.toml"
    spec_path.write_text('name = "cluster"\nstop_time = 60\n'
                         '[controllers]\npd = { scenario = "waves_pd" }\n'
                         'mine = { autopilot = "mine.fmu" }\n'
                         f'[axes]\nwave_seed = {{ start = 1, count = {RUNS // 2} }}\n')
    spec = Spec.read(spec_path)
    with Client(scheduler_file=str(scheduler_file)) as client:
        client.wait_for_workers(2, timeout=60)
        where = client.run(lambda: __import__("cosim").__file__)
        assert all(not Path(path).is_relative_to(ROOT) for path in where.values()), where

    executions = tmp_path / "executions.log"

    def slow_counted_task(job, blobs):      # defined here, so that it travels by value
        with open(executions, "a") as log:
            log.write(job.run["run_id"] + "\n")
        time.sleep(0.3)
        return run_one(job, blobs)

    out = tmp_path / "out"
    out.mkdir()
    result = {}
    running = threading.Thread(target=lambda: result.update(rows=campaign.execute(
        spec, out, scheduler_file=str(scheduler_file), progress=False,
        task=slow_counted_task, no_worker_timeout=30)), daemon=True)
    running.start()
    journal = out / "runs.jsonl"
    deadline = time.monotonic() + 120
    while running.is_alive() and time.monotonic() < deadline and (
            not journal.exists() or len(journal.read_text().splitlines()) < 3):
        time.sleep(0.05)
    killed_after = len(journal.read_text().splitlines())
    os.killpg(processes[1].pid, signal.SIGKILL)            # a worker and its nanny, gone
    running.join(timeout=120)

    assert not running.is_alive(), "the sweep did not end within 120 s of the kill"
    rows = result["rows"]
    assert killed_after < RUNS                             # mid-sweep
    assert len(rows) == RUNS and all(r["status"] == "ok" for r in rows), [r["error"] for r in rows]
    assert len(journal.read_text().splitlines()) == RUNS             # each row once
    ran = executions.read_text().split()
    assert len(ran) - len(set(ran)) <= 1      # recomputed: at most the one run in flight
    local = tmp_path / "local"                             # the same sweep, LocalCluster
    local.mkdir()
    here = campaign.execute(spec, local, workers=2, progress=False)
    assert {r["run_id"]: r["J"] for r in rows} == {r["run_id"]: r["J"] for r in here}


def test_a_worker_running_other_code_is_refused_by_name():
    class Client:                          # what check_workers asks of a client
        def run(self, function, on_error):
            return {"tcp://10.0.0.7:4000": {"code": "0.0.9 (code 123456789abc)"},
                    "tcp://10.0.0.8:4000": function()}

    with pytest.raises(SweepError) as refused:
        check_workers(Client())
    assert "tcp://10.0.0.7:4000 runs ship-autopilot-cosim 0.0.9 (code 123456789abc)" in str(
        refused.value)
    assert "tcp://10.0.0.8:4000" not in str(refused.value)


def test_a_local_cluster_whose_worker_dies_as_it_starts_says_so(monkeypatch):
    """Issue 38: a worker that died while the local cluster started gave a raw 'Nanny failed
    to start'."""
    from cosim.studies import cluster

    def dying(*args, **kwargs):
        raise RuntimeError("Nanny failed to start.")
    monkeypatch.setattr(cluster, "LocalCluster", dying)
    with pytest.raises(cluster.ClusterError, match="the local Dask cluster could not start: a "
                                                   "worker process failed as it started "
                                                   r"\(RuntimeError: Nanny failed to start.\)"):
        cluster.connect(workers=1)
