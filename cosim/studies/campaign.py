"""A sweep run end to end, resumed from its journal (docs/sweeps.md)."""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from ..core.files import FolderBusy, FolderLock
from ..core.watchdog import Limits
from .cluster import CONNECT_TIMEOUT, SweepError, connect
from .sweep_client import Journal, read_rows, run_on_cluster
from .sweep_spec import Spec
from .sweep_task import BATCH, run_batch, run_one

NO_WORKER_TIMEOUT = 60.0        # s a sweep waits while its cluster has no worker


def execute(spec: Spec, out: Path, scheduler: str | None = None, workers: int | None = None,
            progress: bool = True, task=None, scheduler_file: str | None = None,
            backend: str = "fmi", no_worker_timeout: float = NO_WORKER_TIMEOUT,
            connect_timeout: float = CONNECT_TIMEOUT, limits: Limits = Limits(),
            batch_size: int | None = None, batch_task=None) -> list[dict]:
    """Run every run of ``spec`` without an ok row in ``out``'s journal; every row. SweepError
    if a worker runs other code or another sweep writes ``out``; ClusterError for no cluster."""
    try:
        with FolderLock(out):
            journal = Journal(out / "runs.jsonl")
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
    except FolderBusy as busy:
        raise SweepError(str(busy)) from None
    return completed(spec, out)


def completed(spec: Spec, out: Path) -> list[dict]:
    """A row for each combination whose group's result is in the journal, as its own."""
    rows = read_rows(out / "runs.jsonl", quiet=True)
    found = {}
    for group in spec.shared_runs():
        result = _result(group, rows)
        for run in group if result is not None else []:
            found[run["run_id"]] = row = {**result, **run, "ran_as": result["run_id"],
                                          "command": spec.replay(run)}
            if result["run_id"] != run["run_id"]:
                row.pop("track", None)          # drawn once, by the run it is
    return [found[r["run_id"]] for r in spec.runs() if r["run_id"] in found]


def _result(group: list[dict], rows: dict[str, dict]) -> dict | None:
    """A group's row: a member's ok row, else a member's failed row, else None."""
    mine = [rows[r["run_id"]] for r in group if r["run_id"] in rows]
    return next((r for r in mine if r["status"] == "ok"), mine[0] if mine else None)


def run_locally(spec: Spec, run: dict[str, Any], backend: str = "fmi",
                limits: Limits = Limits()) -> dict[str, Any]:
    """One run of ``spec`` in this process, as a worker would (on "batch": a batch of one)."""
    job = spec.job(run, "local", "inprocess" if backend == BATCH else backend, limits)
    blobs = {sha: spec.files()[sha].read_bytes() for sha in job.bundle.fmu_hashes()}
    return run_batch([job], blobs)[0] if backend == BATCH else run_one(job, blobs)
