"""Dask clusters for ensembles of co-simulations: a local one, or an existing scheduler.

Our co-simulations hold the GIL for their whole run, so a worker runs one at a
time: a local cluster has one single-threaded worker process per core.
"""
from __future__ import annotations

import logging

from dask.distributed import Client, LocalCluster


def local_cluster(workers: int | None = None) -> LocalCluster:
    """``workers`` single-threaded worker processes (default: one per core), quiet, no dashboard.

    One task in flight per worker thread (worker-saturation 1.0): when a run kills
    its worker, no queued neighbour is counted as having died with it (and failed
    after three deaths).
    """
    import dask

    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=None, silence_logs=logging.ERROR)


def connect(scheduler: str | None, workers: int | None) -> tuple[Client, LocalCluster | None]:
    """A client of the scheduler at ``scheduler``, or of a new local cluster (returned too)."""
    if scheduler:
        return Client(scheduler), None
    cluster = local_cluster(workers)
    return Client(cluster), cluster
