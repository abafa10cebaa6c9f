"""Dask clusters for ensembles of co-simulations: a local one, or an existing scheduler.

Our co-simulations hold the GIL for their whole run, so a worker runs one at a
time: a local cluster has one single-threaded worker process per core, and the
workers of an existing cluster should be started the same way
(``dask worker ADDRESS --nthreads 1 --nworkers N``).
"""
from __future__ import annotations

import logging

from dask.distributed import Client, LocalCluster


def local_cluster(workers: int | None = None) -> LocalCluster:
    """``workers`` single-threaded worker processes (default: one per core), quiet; its web
    server on a free port (the dashboard, where bokeh is installed).

    One task in flight per worker thread (worker-saturation 1.0): when a run kills
    its worker, no queued neighbour is counted as having died with it (and failed
    after three deaths).
    """
    import dask

    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=":0", silence_logs=logging.ERROR)


def connect(scheduler: str | None = None, workers: int | None = None,
            scheduler_file: str | None = None) -> tuple[Client, LocalCluster | None]:
    """A client of an existing scheduler, found as Dask's own tools find it (an address,
    a scheduler file, or DASK_SCHEDULER_ADDRESS), or of a new local cluster of ``workers``
    processes (returned too). ValueError for ``workers`` with an existing scheduler, whose
    workers are its own."""
    import dask

    if scheduler and scheduler_file:
        raise ValueError("give the scheduler's address or its file, not both")
    address = scheduler or (None if scheduler_file else dask.config.get("scheduler-address",
                                                                         None))
    if address or scheduler_file:
        if workers is not None:
            raise ValueError("--workers sizes a local cluster; an existing scheduler's workers "
                             "are those started with 'dask worker'")
        return (Client(scheduler_file=scheduler_file) if scheduler_file
                else Client(address)), None
    cluster = local_cluster(workers)
    return Client(cluster), cluster
