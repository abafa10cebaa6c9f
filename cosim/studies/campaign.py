"""A sweep run end to end, resumed from its journal (docs/sweeps.md): its runs submitted to a
Dask cluster (on the batch backend in batches, ``plan``), each row journaled as it completes."""
from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import sys
import uuid
from pathlib import Path
from typing import Any

from distributed import as_completed
from fmukit.timebase import step_count
from tqdm import tqdm

from ..core.files import FolderBusy, FolderLock
from ..core.interrupt import Interrupted, StopSignals
from ..core.isolation import Isolation
from ..core.watchdog import Limits
from ..ensemble import SIGNALS
from .cluster import CONNECT_TIMEOUT, NoWorkers, SweepError, check_workers, connect, say, watched
from .sweep_spec import Spec
from .sweep_task import (BATCH, Job, SweepTeardown, batch_refusal, blank_row, noted, run_batch,
                         run_one)

MAX_BATCH = 1024            # the most runs a batch gets unless --batch-size says
BATCH_MEMORY = 128 << 20    # bytes a batch's recorded signals may take on its worker
MIN_BATCH = 32              # the fewest runs a batch is cut down to for keeping workers busy
WAVES_SHARE = 128           # the fewest a batch in waves is cut down to for sharing workers
NO_WORKER_TIMEOUT = 60.0        # s a sweep waits while its cluster has no worker


def execute(spec: Spec, out: Path, scheduler: str | None = None, workers: int | None = None,
            progress: bool = True, task=None, scheduler_file: str | None = None,
            backend: str = "fmi", no_worker_timeout: float = NO_WORKER_TIMEOUT,
            connect_timeout: float = CONNECT_TIMEOUT, limits: Limits = Limits(),
            batch_size: int | None = None, batch_task=None,
            isolation: Isolation = Isolation("foreign")) -> list[dict]:
    """Run every run of ``spec`` without an ok row in ``out``'s journal; every row. SweepError
    if a worker runs other code or another sweep writes ``out``; ClusterError for no cluster."""
    try:
        with FolderLock(out):
            journal = Journal(out / "runs.jsonl")
            groups = spec.shared_runs()
            todo = [group[0] for group in groups
                    if (_result(group, journal.rows) or {}).get("status") != "ok"]
            if len(todo) < len(groups):
                say(f"{len(groups) - len(todo)} of {len(groups)} runs already done in "
                    f"{journal.path}; {len(todo)} to run")
            if todo:
                run_on_cluster(spec, todo, journal,
                               connect(scheduler, workers, scheduler_file, connect_timeout),
                               progress, task or run_one, backend, no_worker_timeout,
                               limits.check(), batch_task or run_batch, batch_size, isolation)
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
                limits: Limits = Limits(), isolation: Isolation = Isolation("foreign")
                ) -> dict[str, Any]:
    """One run of ``spec`` in this process, as a worker would (on "batch": a batch of one)."""
    job = spec.job(run, "local", "inprocess" if backend == BATCH else backend, limits, isolation)
    blobs = {sha: spec.files()[sha].read_bytes() for sha in job.bundle.fmu_hashes()}
    return run_batch([job], blobs)[0] if backend == BATCH else run_one(job, blobs)


def read_rows(path: Path, quiet: bool = False) -> dict[str, dict]:
    """A journal's rows by run id, the last for each; a torn line is skipped, with a warning."""
    rows: dict[str, dict] = {}
    for number, line in enumerate(path.read_bytes().splitlines() if path.exists() else [], 1):
        try:
            row = json.loads(line)              # bytes: not UTF-8 is a ValueError
            rows[row["run_id"]] = row
        except (ValueError, KeyError, TypeError):
            if line.strip() and not quiet:
                print(f"warning: {path}:{number} is not a whole journal row (a write cut "
                      "short?); skipped, its run is done again", file=sys.stderr)
    return rows


class Journal:
    """A sweep's journal, opened by its one writer (who holds the folder's ``FolderLock``)."""

    def __init__(self, path: Path):
        if path.is_symlink():
            raise SweepError(f"the sweep journal {path} is a symbolic link; remove it (a "
                             "journal is read and written only as a file of its own)")
        self.path, self.rows = path, read_rows(path)
        if path.exists() and path.read_bytes()[-1:] not in (b"", b"\n"):  # a torn last line
            with open(path, "ab") as f:
                f.write(b"\n")

    def add(self, row: dict) -> None:
        """Append ``row``, on disk before it returns; never through a symbolic link."""
        handle = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT |
                         getattr(os, "O_NOFOLLOW", 0), 0o644)
        with open(handle, "a") as f:
            f.write(json.dumps(row) + "\n")
            f.flush()
            os.fsync(f.fileno())
        self.rows[row["run_id"]] = row


def batch_limit(job: Job) -> int:
    """The most runs a batch of ``job``'s system and stop time gets by default (memory)."""
    system = job.bundle.system
    stop = system.stop_time if job.stop_time is None else job.stop_time
    rows = step_count(system.start_time, stop, system.step_size) + 1
    return max(1, min(MAX_BATCH, BATCH_MEMORY // (len(SIGNALS) * 8 * rows)))


def batch_counts(groups: list[list[Job]], workers: int, size: int | None = None) -> list[int]:
    """Batches per group (one system and stop time): of ``size``, else as docs/sweeps.md says."""
    if size:
        return [math.ceil(len(group) / size) for group in groups]
    counts = [math.ceil(len(group) / batch_limit(group[0])) for group in groups]
    counts = [max(count, min(workers, len(group) // WAVES_SHARE)) if _in_waves(group[0])
              else count for count, group in zip(counts, groups)]
    while groups and sum(counts) < workers:      # none: every run alone
        largest = max(range(len(groups)), key=lambda g: len(groups[g]) / counts[g])
        if len(groups[largest]) // (counts[largest] + 1) < MIN_BATCH:
            break
        counts[largest] += 1
    return counts


def _in_waves(job: Job) -> bool:
    ship = job.bundle.system.parameters(job.overrides).get("ship", {})
    return float(ship.get("Hs", 0.0)) > 0.0


def plan(spec: Spec, jobs: list[Job], workers: int, size: int | None = None
         ) -> tuple[list[list[Job]], list[Job]]:
    """(the batches, the runs the kernel does not cover) on the batch backend."""
    groups: dict[tuple[str, float | None] | None, list[Job]] = {}
    for job in jobs:                            # None: the runs the kernel does not cover
        covered = spec.batch_coverage[job.run["controller"]] is None
        groups.setdefault((job.bundle.digest, job.stop_time) if covered else None, []).append(job)
    alone = groups.pop(None, [])
    batches = []                                # each group in near-equal parts, in order
    for group, count in zip(groups.values(), batch_counts(list(groups.values()), workers, size)):
        cuts = [round(k * len(group) / count) for k in range(count + 1)]
        batches += [group[a:b] for a, b in zip(cuts, cuts[1:])]
    return batches, alone


def run_on_cluster(spec: Spec, todo: list[dict], journal: Journal, connection, progress: bool,
                   task, backend: str, no_worker_timeout: float, limits: Limits,
                   batch_task=run_batch, batch_size: int | None = None,
                   isolation: Isolation = Isolation("foreign")) -> None:
    """Run ``todo`` on ``connection`` (client, local cluster or None), journaling each row."""
    client, cluster = connection
    teardown = SweepTeardown(uuid.uuid4().hex[:12])
    token, tasks, shipped = teardown.sweep, {}, {}
    try:
        check_workers(client)
        client.register_plugin(teardown)
        # FMUs as tasks, not scattered data (a task lost with its worker is computed again),
        # keyed by sweep (another sweep's release of a shared key would strand these runs).
        shipped = {sha: client.submit(bytes, fmu.read_bytes(), key=f"fmu-{token}-{sha}", pure=False)
                   for sha, fmu in spec.files().items()}
        completions = as_completed(loop=client.loop, with_results=True, raise_errors=False)

        def submit(jobs: list[Job], batch: bool, why: str = "") -> None:
            blobs = {sha: shipped[sha] for sha in jobs[0].bundle.fmu_hashes()}
            kind, what = ("batch", batch_task) if batch else ("run", task)
            future = client.submit(what, jobs if batch else jobs[0], blobs, retries=2,
                                   pure=False, key=f"{kind}-{token}-{jobs[0].run['run_id']}")
            tasks[future] = jobs, batch, why        # why its runs are not in a batch
            completions.add(future)

        route = "inprocess" if backend == BATCH else backend  # a batch's runs alone: in-process
        jobs = [spec.job(run, token, route, limits, isolation) for run in todo]
        together, alone = (plan(spec, jobs, sum(client.nthreads().values()) or 1, batch_size)
                           if backend == BATCH else ([], jobs))
        if together:
            _say_batch_refusals(client)
        for batch in together:
            submit(batch, True)
        for job in alone:
            submit([job], False)
        with tqdm(total=len(todo), desc=spec.name, unit="run", file=sys.stderr,
                  disable=None if progress else True) as bar:   # None: only on a terminal
            for future, result in watched(client, completions, no_worker_timeout):
                jobs, batch, why = tasks.pop(future)
                if future.status == "error":    # the worker died on every retry
                    died = f"{type(result[1]).__name__}: {result[1]}"
                    if batch:                   # each run alone: only a run that kills fails
                        future.release()
                        for job in jobs:
                            submit([job], False, f"its batch's worker died, {died}")
                        continue
                    result = {**blank_row(jobs[0].run, died), "backend": jobs[0].backend}
                rows = result if batch else [result]
                for job, row in zip(jobs, rows, strict=True):
                    journal.add({**(noted(row, why) if why else row),
                                 "command": spec.replay(job.run)})
                future.release()                # done: nothing to recompute if a worker dies
                bar.update(len(rows))
    except BaseException as stopped:
        if isinstance(stopped, NoWorkers):
            client.cancel([*tasks, *shipped.values()])
        _close(client, cluster, teardown, journal, stopped)
        raise
    _close(client, cluster, teardown, journal)


def _say_batch_refusals(client) -> None:
    try:
        refusals = client.run(batch_refusal, on_error="return")
    except Exception:                       # a worker gone: its runs' rows will say
        return
    said: dict[str, list[str]] = {}
    for address, reason in sorted(refusals.items()):
        if reason is not None:
            said.setdefault(str(reason), []).append(address)
    for reason, addresses in said.items():
        say(f"note: the batch route is refused on {len(addresses)} worker"
            f"{'s' if len(addresses) > 1 else ''} ({', '.join(addresses)}): {reason}; "
            "their batches run one run at a time on the in-process route")


def _close(client, cluster, teardown: SweepTeardown, journal: Journal,
           stopped: BaseException | None = None) -> None:      # a shared cluster: FMUs freed
    level = logging.root.manager.disable         # distributed's loggers set their own levels
    with contextlib.ExitStack() as stack:
        stack.callback(logging.disable, level)
        logging.disable(logging.CRITICAL if stopped is not None else level)
        if isinstance(stopped, Interrupted):
            again = stack.enter_context(StopSignals())
            again.received = stopped.signal         # the next one is the second
            again.keep(lambda: f"{journal.path} keeps every run done ({len(journal.rows)})")
        if cluster is None:
            with contextlib.suppress(Exception):     # workers gone with Ctrl-C
                client.unregister_worker_plugin(teardown.name)
        client.close()
        if cluster is not None:
            cluster.close()
