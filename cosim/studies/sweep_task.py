"""A sweep's tasks on a worker: one co-simulation (``run_one``) or a batch of one system's runs
(``run_batch``), the same row either way; masters kept per sweep, thread, system and backend;
the FMUs sent by SHA-256, kept in the worker's private cache (``fmu_cache``), checked when used."""
from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import math
import os
import stat
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from distributed import WorkerPlugin

from .. import ensemble
from ..core.files import write_atomically
from ..core.isolation import Isolation
from ..core.master import BACKENDS, Master
from ..core.ssd import SystemDescription
from ..core.watchdog import Limits, Watchdog
from ..provenance import code_version
from .merit import METRICS, run_metrics, track

BATCH = "batch"                         # the sweep backend of ``run_batch``
SWEEP_BACKENDS = (*BACKENDS, BATCH)


class UnsafeCache(RuntimeError):
    """The FMU cache is not private: whoever else may write it could change the FMUs run."""


@dataclass(frozen=True)
class Bundle:
    """A controller's system as a worker rebuilds it."""
    system: SystemDescription          # component sources: "<sha256>.fmu"
    digest: str                        # SHA-256 of the system and its FMUs' contents

    def fmu_hashes(self) -> set[str]:
        return {Path(c.source).stem for c in self.system.components.values()}


def file_hash(path: Path) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def fmu_cache() -> Path:
    """Where a worker keeps the FMUs it was sent: $COSIM_FMU_CACHE, else cosim-fmus in
    $XDG_CACHE_HOME or ~/.cache, made 0o700; UnsafeCache unless only this user may write it."""
    folder = Path(os.environ.get("COSIM_FMU_CACHE")
                  or Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
                  / "cosim-fmus")
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    facts = os.lstat(folder)
    if not stat.S_ISDIR(facts.st_mode):
        raise UnsafeCache(f"the FMU cache {folder} is not a folder (a symbolic link?); remove "
                          "it, or set COSIM_FMU_CACHE to a folder of your own")
    if facts.st_uid != os.getuid() or facts.st_mode & 0o022:
        whose = (f"belongs to another user (uid {facts.st_uid})" if facts.st_uid != os.getuid()
                 else f"may be written by others (mode {stat.filemode(facts.st_mode)})")
        raise UnsafeCache(f"the FMU cache {folder} {whose}, who could change the FMUs run "
                          "from it; use a folder only you may write (chmod go-w, or set "
                          "COSIM_FMU_CACHE)")
    return folder


def materialise(shipped: Bundle, blobs: dict[str, bytes]) -> SystemDescription:
    """The bundle's system, its FMUs in this machine's cache (a corrupt one written again)."""
    cache = fmu_cache()
    components = {}
    for name, component in shipped.system.components.items():
        sha = Path(component.source).stem
        target = cache / f"{sha}.fmu"
        corrupt = target.exists() and file_hash(target) != sha
        if corrupt:
            print(f"warning: the FMU cache's {target} does not match its hash (a corrupt or "
                  "changed file); written again from the FMU sent", file=sys.stderr)
        if corrupt or not target.exists():
            data = blobs[sha]
            if hashlib.sha256(data).hexdigest() != sha:
                raise ValueError(f"the FMU sent for component '{name}' does not match its "
                                 f"hash {sha[:12]}")
            write_atomically(target, lambda path: path.write_bytes(data))  # noqa: B023
        components[name] = dataclasses.replace(component, source=str(target))
    return dataclasses.replace(shipped.system, components=components)


@dataclass(frozen=True)
class Job:
    """One run as a worker receives it: nothing is read from the client's disk."""
    sweep: str                          # the sweep's token: whose masters these are
    run: dict[str, Any]                 # run_id, controller and axis values
    bundle: Bundle
    overrides: dict[str, dict[str, Any]]
    stop_time: float | None
    track: bool                         # record the track for the tracks figure
    code: str                           # the client's code_version(): the worker's must match
    backend: str = "fmi"                # the master's: fmi, or inprocess for our FMUs
    limits: Limits = Limits()           # the run's step and run time limits
    isolation: Isolation = Isolation("foreign")     # FMUs run in processes of their own


Key = tuple[str, int, str, str, Isolation]   # (sweep, thread, system digest, backend, isolation)
_masters: dict[Key, Any] = {}                   # the idle masters
_busy: dict[Key, Watchdog] = {}                 # the watchdogs of the runs under way
_ended: set[str] = set()                        # the sweeps torn down in this process
_lock = threading.Lock()


def _key(job: Job, isolated: bool = True) -> Key:
    return (job.sweep, threading.get_ident(), job.bundle.digest, job.backend,
            job.isolation if isolated else Isolation())


def _take(job: Job, blobs: dict[str, bytes], watchdog: Watchdog, isolated: bool = True):
    with _lock:
        if job.sweep in _ended:
            raise RuntimeError("the sweep has ended")
        master = _masters.pop(_key(job, isolated), None)
        _busy[_key(job, isolated)] = watchdog
    if master is None:
        return Master(materialise(job.bundle, blobs), backend=job.backend,
                      isolation=job.isolation if isolated else Isolation())
    try:
        master.reset()
    except BaseException:
        master.free()
        raise
    return master


def _give_back(job: Job, master, healthy: bool, isolated: bool = True) -> None:
    with _lock:
        _busy.pop(_key(job, isolated), None)
        keep = master is not None and healthy and job.sweep not in _ended
        if keep:
            _masters[_key(job, isolated)] = master
    if master is not None and not keep:
        master.free()


def free_masters(sweep: str | None = None) -> None:
    """Free the idle masters, all or an ended sweep's (whose busy ones stop and free their own)."""
    with _lock:
        if sweep is not None:
            _ended.add(sweep)
            for watchdog in (w for key, w in _busy.items() if key[0] == sweep):
                watchdog.expired = "the sweep ended"    # it stops at its next beat
        masters = [_masters.pop(k) for k in list(_masters) if sweep in (None, k[0])]
    for master in masters:
        master.free()


class SweepTeardown(WorkerPlugin):
    """Frees one sweep's masters (and their temporary folders) on a worker."""

    def __init__(self, sweep: str):
        self.sweep, self.name = sweep, f"cosim-sweep-{sweep}"

    def teardown(self, worker) -> None:
        free_masters(self.sweep)


def ran_on(kinds: dict[str, str] | None, asked: str) -> str:
    """How a run's components ran: "fmi", "inprocess", or e.g. "inprocess; autopilot: fmi"."""
    if not kinds:
        return asked
    if len(set(kinds.values())) == 1:
        return next(iter(kinds.values()))
    return "; ".join([asked, *(f"{name}: {kind}" for name, kind in kinds.items()
                               if kind != asked)])


def blank_row(run: dict[str, Any], error: str = "") -> dict[str, Any]:
    """A row for ``run``: failed with ``error`` if given, metrics NaN."""
    return {**run, "status": "failed" if error else "ok", "error": error,
            **{m: math.nan for m in METRICS}, "seconds": math.nan, "sim_seconds": math.nan}


def run_one(job: Job, blobs: dict[str, bytes]) -> dict[str, Any]:
    """One co-simulation's row, a failure (past its time limits too) recorded, not raised."""
    started = time.perf_counter()
    if job.code != code_version():          # a worker that joined after the client's check
        return blank_row(job.run, f"worker runs {code_version()}, the client {job.code}: "
                                  "install the client's version on every worker")
    master, watchdog, recording = None, Watchdog(job.limits), None
    try:
        with watchdog:                          # a hung FMU fails its run, not the worker
            watchdog.beat("instantiating the FMUs")
            master = _take(job, blobs, watchdog)
            master.configure(job.overrides)
            simulating = time.perf_counter()
            recording = master.run(job.stop_time, watchdog=watchdog)
        row = result_row(job, recording, time.perf_counter() - simulating)
    except Exception as error:  # a bad setting: not worth retrying
        recording = None
        row = blank_row(job.run, watchdog.expired or f"{type(error).__name__}: {error}")
    finally:
        _give_back(job, master, recording is not None and not recording.error)
    row["backend"] = ran_on(master and master.backends, job.backend)   # same results either way
    row["seconds"] = time.perf_counter() - started
    return row


def result_row(job: Job, recording, sim_seconds: float) -> dict[str, Any]:
    """The row of ``job``'s run from its recording, but its backend and ``seconds``."""
    if recording.error:
        return blank_row(job.run, recording.error)
    row = {**blank_row(job.run), **run_metrics(recording), "sim_seconds": sim_seconds}
    if job.track:
        row["track"] = track(recording)
    return row


def batch_refusal() -> str | None:
    """Why this worker's numpy would not give the in-process bits in a batch, or None."""
    try:
        return ensemble.selftest()
    except Exception as error:          # a self-test that cannot run refuses the route
        return f"its self-test failed: {type(error).__name__}: {error}"


def batch_limits(limits: Limits, members: int) -> Limits:
    """A batch's time limits: each per-run limit times its ``members``."""
    return Limits(*(None if limit is None else limit * members for limit in limits[:2]),
                  limits.grace)


def run_batch(jobs: list[Job], blobs: dict[str, bytes]) -> list[dict[str, Any]]:
    """``run_one``'s rows of ``jobs`` (one system and stop time) computed together, or alone."""
    started = time.perf_counter()
    if any(job.code != code_version() for job in jobs):
        return [run_one(job, blobs) for job in jobs]
    failed = batch_refusal()
    if failed:
        return [noted(run_one(job, blobs), f"the batch route is refused on this worker: "
                                           f"{failed}") for job in jobs]
    watchdog = Watchdog(batch_limits(jobs[0].limits, len(jobs)))
    master, failed = None, "stopped"
    try:
        with watchdog:
            watchdog.beat("instantiating the FMUs")
            master = _take(jobs[0], blobs, watchdog, isolated=False)    # the kernel's settings
            members = []
            for job in jobs:                    # one the master refuses: run_one says why
                with contextlib.suppress(Exception):
                    master.configure(job.overrides)
                    members.append(job)
            watchdog.beat(f"the batch of {len(members)} runs")
            recordings = ensemble.simulate_members(
                master.system, [job.overrides for job in members], jobs[0].stop_time,
                beat=watchdog.beat) if members else []
        failed = watchdog.expired
    except Exception as error:
        failed = watchdog.expired or f"{type(error).__name__}: {error}"
    finally:
        _give_back(jobs[0], master, not failed, isolated=False)
    if failed:
        return [noted(run_one(job, blobs), f"the batch failed, {failed}; run alone")
                for job in jobs]
    share = (time.perf_counter() - started) / max(1, len(members))
    rows = {job.run["run_id"]: {**result_row(job, recording, recording.meta.get("wall_time_s")),
                                "backend": member_backend(recording.meta), "seconds": share}
            for job, recording in zip(members, recordings, strict=True)}
    return [rows.get(job.run["run_id"]) or run_one(job, blobs) for job in jobs]


def noted(row: dict[str, Any], why: str) -> dict[str, Any]:
    """``row`` with why its run did not run in a batch added to its backend."""
    return {**row, "backend": f"{row.get('backend', 'inprocess')} (not in a batch: {why})"}


def member_backend(meta: dict[str, Any]) -> str:
    """A batch member's backend column: "batch", or how it ran alone and why."""
    if meta.get("backend") == BATCH:
        return BATCH
    ran = ran_on(meta.get("backends"), meta.get("backend", "inprocess"))
    notes = "; ".join(meta.get("notes") or [])
    return f"{ran} ({notes})" if notes else ran
