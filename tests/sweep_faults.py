"""A sweep task that kills its worker process for one run: the retry path."""
import os

from cosim.studies.sweep import run_one


def killing_task(spec, run):
    if run["wave_seed"] == 2:
        os._exit(3)                 # the worker dies; Dask retries, then gives up
    return run_one(spec, run)
