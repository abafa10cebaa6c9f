"""A sweep task that kills its worker process for one run: the retry path."""
import os

from cosim.studies.sweep_task import run_one


def killing_task(job, blobs):
    if job.run["wave_seed"] == 2:
        os._exit(3)                 # the worker dies; Dask retries, then gives up
    return run_one(job, blobs)

