"""Dask clusters for ensembles of co-simulations: a local one, or an existing scheduler.

Our co-simulations hold the GIL for their whole run, so a worker runs one at a
time: a local cluster has one single-threaded worker process per core, and the
workers of an existing cluster should be started the same way
(``dask worker ADDRESS --nthreads 1 --nworkers N``).
"""
from __future__ import annotations

import json
import logging
import os
import signal
import sys
from pathlib import Path

from dask.distributed import Client, LocalCluster

from ..core.files import read_small_text


def local_cluster(workers: int | None = None) -> LocalCluster:
    """``workers`` single-threaded worker processes (default: one per core), quiet; its web
    server on a free port (the dashboard, where bokeh is installed).

    One task in flight per worker thread (worker-saturation 1.0): when a run kills
    its worker, no queued neighbour is counted as having died with it (and failed
    after three deaths).

    The cluster is made with SIGINT blocked in this thread: the threads it starts here
    (its event loop, which starts and restarts the workers) and the worker processes
    they start (a blocked signal stays blocked through exec) never take it. A Ctrl-C at
    a terminal goes to every process of its group; the client alone stops, and closes
    the workers, instead of each worker printing its traceback. A Ctrl-C while the
    cluster starts arrives once it has started (and closes it).
    """
    import dask

    _start_resource_tracker()
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    cluster = None
    try:
        with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0", silence_logs=logging.ERROR)
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)   # a Ctrl-C meanwhile: here
    except BaseException:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
        if cluster is not None:
            cluster.close()
        raise
    return cluster


def _start_resource_tracker() -> None:
    """Start multiprocessing's resource tracker (if it is not running) with its standard
    error on the null device: before SIGINT is blocked, since starting it unblocks SIGINT
    in the thread that does; and quiet, since all it would ever tell the user is that Dask's
    queues leaked semaphores, when a second Ctrl-C ended the process at once."""
    from multiprocessing import resource_tracker

    sys.stderr.flush()
    saved, null = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 2)
        resource_tracker.ensure_running()
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)


class ClusterError(ValueError):
    """No cluster to run on: the scheduler cannot be reached or found, or the options that
    say where it is or how big a local one is make no sense (a ValueError: of the options)."""


CONNECT_TIMEOUT = 30.0
"""Seconds a client tries to reach an existing scheduler (Dask's own default)."""
SCHEDULER_FILE_BYTES = 1 << 20
"""The largest scheduler file read (Dask writes a few hundred bytes)."""


def local_workers(workers: int | None) -> tuple[int | None, str | None]:
    """The number of worker processes of a local cluster for the ``workers`` asked (None:
    Dask's default, one per core), and a note where it was capped at the cores this
    process may use (a run holds the GIL: more processes than cores only share them).
    ClusterError for fewer than one."""
    from dask.system import CPU_COUNT

    if workers is None:
        return None, None
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ClusterError(f"--workers {workers!r}: a local cluster needs at least one worker")
    if workers > CPU_COUNT:
        return CPU_COUNT, (f"--workers {workers}: this machine gives this process "
                           f"{CPU_COUNT} cores, and a run holds one core from start to end; "
                           f"starting {CPU_COUNT} workers")
    return workers, None


def scheduler_address(scheduler_file: str | Path) -> str:
    """The address in a scheduler file (``dask scheduler --scheduler-file``); ClusterError
    naming the file if it is missing, unreadable or holds no address. (Dask's own client
    waits for a missing file to appear, for ever.)"""
    path = Path(scheduler_file)
    if not path.exists():
        raise ClusterError(f"scheduler file {path} does not exist (has the scheduler "
                           "started with --scheduler-file?)")
    try:                                # a scheduler file is a few hundred bytes
        address = json.loads(read_small_text(path, SCHEDULER_FILE_BYTES)).get("address")
    except (ValueError, AttributeError) as error:
        raise ClusterError(f"scheduler file {path} is not a Dask scheduler file (JSON "
                           f"with its address): {error or 'not a JSON object'}") from None
    if not isinstance(address, str) or not address:
        raise ClusterError(f"scheduler file {path} names no scheduler address")
    return address


def connect(scheduler: str | None = None, workers: int | None = None,
            scheduler_file: str | None = None, timeout: float = CONNECT_TIMEOUT
            ) -> tuple[Client, LocalCluster | None]:
    """A client of an existing scheduler, found as Dask's own tools find it (an address,
    a scheduler file, or DASK_SCHEDULER_ADDRESS) and reached within ``timeout`` seconds,
    or of a new local cluster of ``workers`` processes (``local_workers``; returned too).
    ClusterError, naming the address or file, if the scheduler cannot be reached or found,
    or for ``workers`` with an existing scheduler, whose workers are its own."""
    import dask

    if scheduler and scheduler_file:
        raise ClusterError("give the scheduler's address or its file, not both")
    if not 0 < timeout < float("inf"):
        raise ClusterError(f"the connect timeout must be a number of seconds > 0, got "
                           f"{timeout!r}")
    where = "--scheduler" if scheduler else "DASK_SCHEDULER_ADDRESS or Dask's config"
    address = scheduler or (None if scheduler_file else dask.config.get("scheduler-address",
                                                                         None))
    if scheduler_file:
        address, where = scheduler_address(scheduler_file), f"scheduler file {scheduler_file}"
    if address:
        if workers is not None:
            raise ClusterError("--workers sizes a local cluster; an existing scheduler's "
                               "workers are those started with 'dask worker'")
        try:
            return Client(address, timeout=timeout), None
        except ValueError as error:
            raise ClusterError(f"{address!r} (from {where}) is not a Dask scheduler address: "
                               f"{error}") from None
        except Exception as error:      # OSError, or whatever a server that is not one sent
            raise ClusterError(f"cannot reach the Dask scheduler at {address} (from {where}) "
                               f"within {timeout:g} s: {type(error).__name__}: "
                               f"{str(error)[:200]}") from None
    workers, note = local_workers(workers)
    if note:
        print(f"note: {note}", file=sys.stderr)
    cluster = local_cluster(workers)
    return Client(cluster), cluster
