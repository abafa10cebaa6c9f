"""Ensembles of co-simulations on Dask: Monte Carlo over seeds, sea states and settings.

    python -m cosim.sweep docs/sweeps/smc_vs_pd.toml             # local cluster, 1 worker/core
    python -m cosim.sweep SPEC --scheduler tcp://host:8786       # an existing Dask cluster
    python -m cosim.sweep SPEC --workers 2 --csv --out results/sweeps
    python -m cosim.sweep SPEC --backend inprocess               # our FMUs without FMI: faster
    python -m cosim.sweep SPEC --backend batch                   # many runs per task: fastest

SPEC is a TOML file (see docs/sweeps/example.toml):

    name = "example"                       # output folder results/sweeps/<name>/
    stop_time = 400                        # s, optional (default: the scenario's)

    [controllers]                          # the controller axis: base scenario and settings
    pd = { scenario = "waves_pd" }
    smc = { scenario = "waves_smc", set = { "autopilot.eta_h" = 10.0 } }
    mine = { autopilot = "my.fmu", map = { psi = "heading" } }   # your own, in waves_pd
    other = "path/to/other.ssd"            # or a scenario, or an autopilot FMU, alone

    [axes]                                 # every combination (see below: calm water)
    wave_seed = { start = 1, count = 20 }  # or a list
    sea_state = [0, 2, 3]                  # WMO codes -> Hs, T0 at 1:70 (cosim.analysis.seastate)
    Hs = [0.005]                           # m (instead of sea_state); T0 likewise
    psi_w = [3.14159]                      # rad, wave direction
    route = ["0,0;30,0;60,25;90,25"]       # guidance waypoints
    "ship.delta_rate_max" = [0.0873, 0.349] # any FMU parameter, component.variable

    [plots]
    map = ["sea_state", "ship.delta_rate_max"]   # axes of the J_SMC / J_PD map
    tracks = { sea_state = 3 }             # overlay the tracks of these runs (all seeds)

Without [controllers], pd and smc run on waves_pd and waves_smc. Paths are relative
to the sweep file; an autopilot FMU must keep the port contract of
``cosim.scenarios.autopilot``.

Each Dask task is one whole co-simulation with our master (``sweep_task``). The
client sends every FMU once, by content (``bundle``): a worker needs the project
installed, nothing else, and runs the client's code or is refused. A worker keeps
each system's FMUs per thread and resets them (fmi2Reset) between tasks.

--backend batch runs the runs of each PD, PID or SMC course-keeping system as batches,
one task each (``cosim.ensemble``: the members stepped together as numpy arrays), with
every row's columns the in-process route's, bit for bit, but backend, seconds and
sim_seconds (the run's share of its batch). --batch-size caps a batch's runs (default:
as few batches as keep every worker busy, of 32 to 1,024 runs where there are that many,
and in waves a share of each system for every worker; ``sweep_client.batch_counts``).
A system the kernel does not cover (a foreign autopilot FMU) runs in-process, one run per
task, with a note; so does every run of a batch that fails as a whole, and of a worker
whose self-test refuses the route (said once), each row saying why in its backend. A
batch's time limits are the per-run limits times its runs.

A run's id hashes everything that determines its result (the system and its FMUs'
contents, the settings, the stop time, the axis values). Combinations that differ
only in settings that change nothing run once, and the command says so: in calm
water (Hs = 0) the wave seed, T0, psi_w and wave_components make no difference, bit
for bit, so "sea_state 0 is calm water (Hs = 0): the wave_seed axis does not apply
there; 2 runs instead of 6". results/sweeps/<name>/runs.jsonl gets each row as it
completes (``journal``), so an interrupted sweep resumes where it stopped; failed
runs are run again then (a deterministic failure fails again at once, one caused by
a lost worker deserves its retry). results.parquet (and results.csv with --csv, its
headers with their units) hold one row per combination at the end, each with the
run whose result it is (ran_as) and the cosim.run command that reproduces it, bit
for bit (command); summary.csv gives each figure of merit per setting and
controller (median, quartiles, extremes, over the runs of that setting), the
summary of J is printed, figures are written, and comparison.md pairs every
controller with pd seed by seed. A task whose worker dies is retried twice, then
recorded as failed; an FMU error is recorded as failed at once, with its message.
Ctrl-C or SIGTERM, at any stage, ends the command with one line: the runs done and
kept, and the command that resumes (it runs nothing twice); a second one ends it at
once. A sweep whose cluster has had no worker for 60 s (``--no-worker-timeout``)
stops as on Ctrl-C, every row done kept, and says so.

Modules: ``sweep_spec`` reads a spec and lists its runs, ``sweep_client`` drives them
on the cluster, ``sweep_task`` is one run on a worker, ``sweep_tables`` and
``sweep_figures`` present the rows. This module runs a spec (``execute``,
``run_locally``, ``completed``); for the scorecard and the tests it also provides
``Spec``, ``controller_entry``, ``comparison``, ``write_tables``, ``METRICS``,
``SweepError``, ``NoWorkers`` and ``check_workers`` from those modules.
"""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from ..core.watchdog import Limits
from .cluster import CONNECT_TIMEOUT, connect
from .journal import Journal, JournalLocked, read_rows
from .sweep_client import NoWorkers, SweepError, check_workers, run_on_cluster
from .sweep_spec import Spec, controller_entry
from .sweep_tables import comparison, write_tables
from .sweep_task import BATCH, METRICS, SWEEP_BACKENDS, run_batch, run_one

__all__ = ["execute", "completed", "run_locally", "NO_WORKER_TIMEOUT",
           # from the modules above, for the scorecard and the tests
           "Spec", "controller_entry", "comparison", "write_tables", "METRICS", "SweepError",
           "NoWorkers", "check_workers"]

NO_WORKER_TIMEOUT = 60.0
"""Seconds a sweep waits while its cluster has no worker, then stops (``NoWorkers``)."""


def execute(spec: Spec, out: Path, scheduler: str | None = None, workers: int | None = None,
            progress: bool = True, task=None, scheduler_file: str | None = None,
            backend: str = "fmi", no_worker_timeout: float = NO_WORKER_TIMEOUT,
            connect_timeout: float = CONNECT_TIMEOUT, limits: Limits = Limits(),
            batch_size: int | None = None, batch_task=None) -> list[dict]:
    """Run every run of ``spec`` without an ok row in the journal (failed rows are run
    again); return every row of the sweep.

    ``backend``: "fmi" or "inprocess", the master's ("inprocess": this project's FMUs as
    Python classes: the same results, faster; any other FMU runs through FMI,
    ``Spec.backend_notes`` says which), or "batch": the runs of each system the batch
    kernel covers in batches of at most ``batch_size`` runs (default: ``batches``), one
    task each (``batch_task(jobs, blobs) -> rows``, default ``sweep_task.run_batch``),
    the others in-process. The backend is not part of a run's identity: a sweep may be
    resumed with another. ``limits``: each run's step and run time limits
    (``cosim.core.watchdog``; a batch's are these times its runs): a run past them is
    recorded failed, saying which.

    ``task(job, blobs) -> row`` is what each run alone executes (default ``run_one``). Each
    distinct FMU goes to the cluster once (``cosim.studies.bundle``); each task's future
    is released as soon as its rows are journaled, so a lost worker costs only the runs
    it had in flight. On Ctrl-C or SIGTERM (``Interrupted``, raised again once the
    cluster is closed) the runs completed so far stay in the journal (``completed``);
    the same call then resumes. A cluster with no worker for ``no_worker_timeout``
    seconds ends the sweep the same way, with ``NoWorkers``. SweepError if a worker runs
    other code than the client or another sweep writes the journal; ``cluster.ClusterError``
    (a ValueError) if the scheduler cannot be found or reached within ``connect_timeout``
    seconds, or ``workers`` makes no sense; ValueError for another backend, or a
    ``batch_size`` that is not a whole number >= 1 of the batch backend.
    """
    if backend not in SWEEP_BACKENDS:
        raise ValueError(f"backend must be {', '.join(SWEEP_BACKENDS[:-1])} or "
                         f"{SWEEP_BACKENDS[-1]}, got {backend!r}")
    if batch_size is not None and backend != BATCH:
        raise ValueError(f"batch_size is the batch backend's, not the {backend} backend's")
    if batch_size is not None and (isinstance(batch_size, bool)
                                   or not isinstance(batch_size, int) or batch_size < 1):
        raise ValueError(f"batch_size must be a whole number >= 1, got {batch_size!r}")
    if not 0 < no_worker_timeout < float("inf"):
        raise ValueError(f"no_worker_timeout must be a number of seconds > 0, got "
                         f"{no_worker_timeout!r}")
    try:
        with Journal(out / "runs.jsonl") as journal:
            groups = spec.shared_runs()
            todo = [group[0] for group in groups
                    if (_result(group, journal.rows) or {}).get("status") != "ok"]
            if len(todo) < len(groups):
                print(f"{len(groups) - len(todo)} of {len(groups)} runs already done in "
                      f"{journal.path}; {len(todo)} to run", file=sys.stderr, flush=True)
            if todo:
                run_on_cluster(spec, todo, journal,
                               connect(scheduler, workers, scheduler_file, connect_timeout),
                               progress, task or run_one, backend, no_worker_timeout,
                               limits.check(), batch_task or run_batch, batch_size)
    except JournalLocked as locked:
        raise SweepError(str(locked)) from None
    return completed(spec, out)


def completed(spec: Spec, out: Path) -> list[dict]:
    """A row for each combination of ``spec`` whose result is in its journal, in the order
    of ``spec.runs()``: the result of its group (``Spec.shared_runs``) with the
    combination's own axis values and run id, ``ran_as`` the run id of the run whose
    result it is (its own, or an equivalent run's; only that row keeps the track), and
    ``command`` the cosim.run command that reproduces it (``Spec.replay``)."""
    rows = read_rows(out / "runs.jsonl", quiet=True)
    found = {}
    for group in spec.shared_runs():
        result = _result(group, rows)
        if result is not None:
            for run in group:
                found[run["run_id"]] = _as_row_of(spec, run, result)
    return [found[r["run_id"]] for r in spec.runs() if r["run_id"] in found]


def _result(group: list[dict], rows: dict[str, dict]) -> dict | None:
    """The journal's row for a group of equivalent runs: a member's ok row, else a member's
    failed row, else None."""
    mine = [rows[r["run_id"]] for r in group if r["run_id"] in rows]
    return next((r for r in mine if r["status"] == "ok"), mine[0] if mine else None)


def _as_row_of(spec: Spec, run: dict, result: dict) -> dict:
    """``result`` (a journal row) as the row of ``run``, an equivalent run."""
    row = {**result, **run, "ran_as": result["run_id"], "command": spec.replay(run)}
    if result["run_id"] != run["run_id"]:
        row.pop("track", None)          # drawn once, by the run it is
    return row


def run_locally(spec: Spec, run: dict[str, Any], backend: str = "fmi",
                limits: Limits = Limits()) -> dict[str, Any]:
    """One run of ``spec`` in this process, as a worker would do it (on "batch", as a batch
    of one)."""
    job = spec.job(run, "local", "inprocess" if backend == BATCH else backend, limits)
    blobs = {sha: spec.files()[sha].read_bytes() for sha in job.bundle.fmu_hashes()}
    return run_batch([job], blobs)[0] if backend == BATCH else run_one(job, blobs)
