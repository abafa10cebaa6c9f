"""Sweep tasks that kill their worker process: the retry path, and a cluster left with none."""
import os
import time
from pathlib import Path

from cosim.studies.sweep_task import run_one

_ran = False                        # this worker process has run a run


def killing_task(job, blobs):
    if job.run["wave_seed"] == 2:
        os._exit(3)                 # the worker dies; Dask retries, then gives up
    return run_one(job, blobs)


def killing_task_after_one_row(job, blobs):
    """The first run in a worker process runs; the next kills the process, once a row is in
    the journal $SWEEP_FAULTS_JOURNAL (the first run's result fetched: not lost with it)."""
    global _ran
    if _ran:
        journal = Path(os.environ["SWEEP_FAULTS_JOURNAL"])
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (journal.exists() and journal.stat().st_size):
            time.sleep(0.05)
        os._exit(3)
    _ran = True
    return run_one(job, blobs)
