"""Dask clusters for sweeps, their workers checked before any run and watched while it goes. A
run holds the GIL throughout: a worker is one single-threaded process (``--nthreads 1``)."""
from __future__ import annotations

import importlib.util
import json
import logging
import os
import signal
import sys
import time
from multiprocessing import resource_tracker
from pathlib import Path
from typing import Any, Iterator

import dask
from dask.distributed import Client, LocalCluster, as_completed
from dask.system import CPU_COUNT

from ..core.files import read_small_text
from ..provenance import PACKAGE, code_version
from .sweep_task import UnsafeCache, fmu_cache

CONNECT_TIMEOUT = 30.0          # s a client tries to reach a scheduler (Dask's default)


class ClusterError(ValueError):
    """No cluster to run on: no scheduler reached or found, or options that make no sense."""


class SweepError(RuntimeError):
    """The sweep cannot start: a worker runs other code, or another sweep writes its folder."""


class NoWorkers(RuntimeError):
    """The sweep stopped: its cluster had no worker for as long as it waits for one."""

    exit_status = 3


def local_cluster(workers: int | None = None) -> LocalCluster:
    """Quiet single-threaded workers (default: one per core), worker-saturation 1.0 (a run that
    kills its worker takes no queued run with it), made with SIGINT blocked: a Ctrl-C stops the
    client alone. Its resource tracker is started first (that unblocks SIGINT) and muted."""
    sys.stderr.flush()
    saved, null = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 2)
        resource_tracker.ensure_running()
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    cluster = None
    try:
        with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0", silence_logs=logging.CRITICAL)
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)   # a Ctrl-C meanwhile: here
    except BaseException as error:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        if cluster is not None:
            cluster.close()
        if isinstance(error, Exception):    # e.g. 'Nanny failed to start': a worker died
            raise ClusterError(f"the local Dask cluster could not start: a worker process "
                               f"failed as it started ({type(error).__name__}: "
                               f"{str(error)[:200]}); try again, or give --workers fewer"
                               ) from error
        raise
    return cluster


def local_workers(workers: int | None) -> int | None:
    """``workers`` (None: one per core; the commands refuse < 1) capped, with a note, at the
    cores this process has."""
    if workers is None or workers <= CPU_COUNT:
        return workers
    print(f"note: --workers {workers}: this machine gives this process {CPU_COUNT} cores, and "
          f"a run holds one core from start to end; starting {CPU_COUNT} workers", file=sys.stderr)
    return CPU_COUNT


def scheduler_address(scheduler_file: str | Path) -> str:
    """The address in a scheduler file, or ClusterError (Dask's client waits for ever)."""
    path = Path(scheduler_file)
    if not path.exists():
        raise ClusterError(f"scheduler file {path} does not exist (has the scheduler "
                           "started with --scheduler-file?)")
    try:                                # a scheduler file is a few hundred bytes
        address = json.loads(read_small_text(path, 1 << 20)).get("address")
    except (ValueError, AttributeError) as error:
        raise ClusterError(f"scheduler file {path} is not a Dask scheduler file (JSON "
                           f"with its address): {error or 'not a JSON object'}") from None
    if not isinstance(address, str) or not address:
        raise ClusterError(f"scheduler file {path} names no scheduler address")
    return address


def connect(scheduler: str | None = None, workers: int | None = None,
            scheduler_file: str | None = None, timeout: float = CONNECT_TIMEOUT
            ) -> tuple[Client, LocalCluster | None]:
    """(client, local cluster or None) of the scheduler Dask's tools find, else a local one."""
    if scheduler and scheduler_file:
        raise ClusterError("give the scheduler's address or its file, not both")
    if scheduler_file:
        address, where = scheduler_address(scheduler_file), f"scheduler file {scheduler_file}"
    else:
        address = scheduler or dask.config.get("scheduler-address", None)
        where = "--scheduler" if scheduler else "DASK_SCHEDULER_ADDRESS or Dask's config"
    if not address:
        cluster = local_cluster(local_workers(workers))
        return Client(cluster), cluster
    if workers is not None:
        raise ClusterError("--workers sizes a local cluster; an existing scheduler's "
                           "workers are those started with 'dask worker'")
    try:
        return Client(address, timeout=timeout), None
    except ValueError as error:
        raise ClusterError(f"{address!r} (from {where}) is not a Dask scheduler address: "
                           f"{error}") from None
    except Exception as error:          # OSError, or whatever a server that is not one sent
        raise ClusterError(f"cannot reach the Dask scheduler at {address} (from {where}) "
                           f"within {timeout:g} s: {type(error).__name__}: "
                           f"{str(error)[:200]}") from None


def watched(client, futures: as_completed, timeout: float) -> Iterator[tuple[Any, Any]]:
    """``futures`` (``with_results``) as they complete, raising ``NoWorkers`` once the cluster
    has had no worker for ``timeout`` s (``as_completed``'s timeout is one deadline for all)."""
    interval = max(0.05, min(1.0, timeout / 4))         # Dask fails a shorter wait
    seen, gone = False, None                            # gone: since when none counted
    while not futures.is_empty():
        batch = futures.next_batch(block=False)
        yield from batch
        if batch:
            continue
        try:
            workers = len(client.nthreads())
        except OSError:                     # the scheduler cannot be reached: no worker either
            workers = 0
        if workers:
            seen, gone = True, None
        elif gone is None:
            gone = time.monotonic(), time.strftime("%Y-%m-%d %H:%M:%S")
        elif time.monotonic() - gone[0] >= timeout:
            since = "the last one left by" if seen else "none has joined since"
            raise NoWorkers(f"no worker in the cluster for {timeout:g} s ({since} "
                            f"{gone[1]}); the sweep stopped")
        with futures.thread_condition:      # woken as soon as one completes
            futures.thread_condition.wait_for(futures.has_ready, timeout=interval)


def say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def worker_facts() -> dict[str, Any]:
    """A worker's code, and why its FMU cache is not safe to run FMUs from ("" if it is)."""
    try:
        fmu_cache()
        unsafe = ""
    except (UnsafeCache, OSError) as error:
        unsafe = str(error)
    return {"code": code_version(), "cache": unsafe}


def check_workers(client) -> None:
    """SweepError naming each worker of other code or an unsafe FMU cache; says the dashboard,
    and warns of workers of several threads or a scheduler that queues runs."""
    mine = code_version()
    try:
        facts = client.run(worker_facts, on_error="return")
    except Exception as error:              # e.g. no worker can import cosim at all
        raise SweepError(f"cannot ask the workers what they run ({error})") from None
    facts = {a: f if isinstance(f, dict) else {"code": f"none ({type(f).__name__}: {f})"}
             for a, f in sorted(facts.items())}
    wrong = [f"  {a} runs {PACKAGE} {f['code']}" for a, f in facts.items() if f["code"] != mine]
    if wrong:
        raise SweepError(f"workers run other code than this client ({PACKAGE} {mine}):\n"
                         + "\n".join(wrong) + "\ninstall the client's version on every worker "
                         "(a wheel: pip wheel --no-deps -w dist . ; pip install dist/*.whl)")
    unsafe = [f"  {a}: {f['cache']}" for a, f in facts.items() if f["cache"]]
    if unsafe:
        raise SweepError("workers whose FMU cache is not safe to run FMUs from:\n"
                         + "\n".join(unsafe))
    dashboard, saturation = client.run_on_scheduler(_scheduler)
    if dashboard:
        say(f"dashboard: {client.dashboard_link}")
    threaded = {a: n for a, n in client.nthreads().items() if n > 1}
    if threaded:
        say(f"warning: {', '.join(f'{a} has {n} threads' for a, n in threaded.items())}; a "
            "run holds the GIL from start to end, so threads of one worker take turns: start "
            "workers with --nthreads 1 and more processes (--nworkers)")
    if saturation != 1.0:
        say(f"warning: the scheduler's worker-saturation is {saturation}: it queues more than "
            "one run per worker thread, and a worker killed by one run takes the queued ones "
            "with it; start the scheduler with DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION=1.0")


def _scheduler(dask_scheduler=None) -> tuple[bool, float]:      # dashboard served, saturation
    return ("dashboard" in dask_scheduler.services and importlib.util.find_spec("bokeh")
            is not None, float(dask_scheduler.WORKER_SATURATION))
