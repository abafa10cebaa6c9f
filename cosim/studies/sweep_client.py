"""A sweep's client side: its runs submitted to a Dask cluster, each row journaled as it
completes, and the cluster watched for workers that run other code, or none at all.

``sweep_task`` is the other side: what a worker runs.
"""
from __future__ import annotations

import logging
import queue
import sys
import time
import uuid
from contextlib import contextmanager
from typing import Iterator

from ..core.interrupt import Interrupted, StopSignals
from ..core.provenance import PACKAGE, code_version
from ..core.watchdog import Limits
from .bundle import UnsafeCache, fmu_cache
from .journal import Journal
from .sweep_spec import Spec
from .sweep_task import SweepTeardown, blank_row, fmu_bytes, worker_facts


# -- the client side --------------------------------------------------------------------
class SweepError(RuntimeError):
    """The sweep cannot start: a worker runs other code, or another sweep holds the journal."""


class NoWorkers(RuntimeError):
    """The sweep stopped: its cluster had no worker for as long as it waits for one. The
    runs completed stay in the journal, as on an interruption."""

    exit_status = 3
    """The command's exit status for it (0: every run ok, 1: some failed, 2: cannot start)."""


class _WorkerWatch:
    """Raises ``NoWorkers`` from ``check`` once the scheduler has counted no worker for
    ``timeout`` seconds; it is asked at most every ``interval`` seconds (1 s, or less for a
    short timeout), and only while the client waits."""

    def __init__(self, client, timeout: float):
        self.client, self.timeout = client, timeout
        self.interval = max(0.05, min(1.0, timeout / 4))   # Dask fails a shorter wait
        self.seen = False                   # a worker was counted at least once
        self.gone_since: float | None = None
        self.gone_at = ""                   # when none was first counted, for the message
        self.next_check = 0.0
        self.check()

    def check(self) -> None:
        now = time.monotonic()
        if now < self.next_check:
            return
        self.next_check = now + self.interval
        try:
            workers = len(self.client.nthreads())
        except OSError:                     # the scheduler cannot be reached: no worker either
            workers = 0
        if workers:
            self.seen, self.gone_since = True, None
        elif self.gone_since is None:
            self.gone_since, self.gone_at = now, time.strftime("%Y-%m-%d %H:%M:%S")
        elif now - self.gone_since >= self.timeout:
            since = "the last one left by" if self.seen else "none has joined since"
            raise NoWorkers(f"no worker in the cluster for {self.timeout:g} s ({since} "
                            f"{self.gone_at}); the sweep stopped")

    def result(self, future):
        """``future.result()``, checking the cluster while it waits: a finished run's result
        is fetched from its worker, and computed again if that worker has just died."""
        from dask.distributed import TimeoutError

        while True:
            try:
                return future.result(timeout=self.interval)
            except TimeoutError:
                if future.status == "error":    # the task's own TimeoutError
                    raise
                self.check()


def _as_completed(futures: list, watch: _WorkerWatch) -> Iterator:
    """Each future as it completes, from its done callback (run by the future's own client,
    not the newest one); while none completes, ``watch`` is checked. Dask's ``as_completed``
    cannot do this: its timeout is a deadline for the whole iteration."""
    done: queue.SimpleQueue = queue.SimpleQueue()
    for future in futures:
        future.add_done_callback(done.put)
    for _ in futures:
        while True:
            try:
                yield done.get(timeout=watch.interval)
                break
            except queue.Empty:
                watch.check()


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def check_workers(client) -> None:
    """SweepError naming each worker that runs other code than this client (or none of
    it), or whose FMU cache is not private to its user; a warning for workers with more than one thread, or a scheduler that queues
    more than one run per thread."""
    mine = code_version()
    try:
        facts = client.run(worker_facts, on_error="return")
    except Exception as error:              # e.g. no worker can import cosim at all
        raise SweepError(f"cannot ask the workers what they run ({error})") from None
    wrong = []
    for address, fact in sorted(facts.items()):
        theirs = fact["code"] if isinstance(fact, dict) else f"none ({type(fact).__name__}: {fact})"
        if theirs != mine:
            wrong.append(f"  {address} runs {PACKAGE} {theirs}")
    if wrong:
        raise SweepError(f"workers run other code than this client ({PACKAGE} {mine}):\n"
                         + "\n".join(wrong) + "\ninstall the client's version on every worker "
                         "(a wheel: pip wheel --no-deps -w dist . ; pip install dist/*.whl)")
    unsafe = {a: problem for a, problem in client.run(_cache_problem).items() if problem}
    if unsafe:
        raise SweepError("workers whose FMU cache is not safe to run FMUs from:\n" + "\n".join(
            f"  {address}: {problem}" for address, problem in sorted(unsafe.items())))
    threaded = {a: n for a, n in client.nthreads().items() if n > 1}
    if threaded:
        _say(f"warning: {', '.join(f'{a} has {n} threads' for a, n in threaded.items())}; a "
             "run holds the GIL from start to end, so threads of one worker take turns: start "
             "workers with --nthreads 1 and more processes (--nworkers)")
    saturation = client.run_on_scheduler(_worker_saturation)
    if saturation != 1.0:
        _say(f"warning: the scheduler's worker-saturation is {saturation}: it queues more than "
             "one run per worker thread, and a worker killed by one run takes the queued ones "
             "with it; start the scheduler with DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION=1.0")


def _cache_problem() -> str:
    """Why this worker's FMU cache is unsafe (``bundle.fmu_cache``), or ""."""
    try:
        fmu_cache()
    except (UnsafeCache, OSError) as error:
        return str(error)
    return ""


def _has_dashboard(dask_scheduler=None) -> bool:
    """Whether the scheduler serves its dashboard (which needs bokeh where it runs)."""
    import importlib.util
    return ("dashboard" in dask_scheduler.services
            and importlib.util.find_spec("bokeh") is not None)


def _worker_saturation(dask_scheduler=None) -> float:
    """The running scheduler's worker-saturation (read at its start from Dask's config)."""
    return float(dask_scheduler.WORKER_SATURATION)


def run_on_cluster(spec: Spec, todo: list[dict], journal: Journal, connection, progress: bool,
                   task, backend: str, no_worker_timeout: float, limits: Limits) -> None:
    """Run ``todo`` (runs of ``spec``) as ``task`` on the cluster of ``connection`` (a
    client and the local cluster it made, or None), journaling each row as it completes;
    the client, and a local cluster, closed on every path (``execute`` documents the rest).
    When the sweep stops early, the cluster closes quietly (``_stopping``)."""
    client, cluster = connection
    teardown = SweepTeardown(uuid.uuid4().hex[:12])
    stopped = None
    try:
        _submit_and_journal(spec, todo, journal, client, progress, task, backend,
                            no_worker_timeout, limits, teardown)
    except BaseException as error:
        stopped = error
        raise
    finally:
        with _stopping(stopped, journal):
            _close(client, cluster, teardown)


def _submit_and_journal(spec: Spec, todo: list[dict], journal: Journal, client, progress: bool,
                        task, backend: str, no_worker_timeout: float, limits: Limits,
                        teardown: SweepTeardown) -> None:
    """Check the workers, send the FMUs and ``todo``, and journal each row as it completes."""
    token = teardown.sweep
    if client.run_on_scheduler(_has_dashboard):
        _say(f"dashboard: {client.dashboard_link}")
    check_workers(client)
    client.register_plugin(teardown)
    # Each FMU as a task holding its bytes, not scattered data: a task's result lost with
    # its worker is computed again, scattered data is gone, and every run with it. Keyed
    # by sweep: another sweep's release of a shared key would strand this one's runs.
    shipped = {sha: client.submit(fmu_bytes, path.read_bytes(), key=f"fmu-{token}-{sha}",
                                  pure=False)
               for sha, path in spec.files().items()}
    futures = {}
    for run in todo:
        job = spec.job(run, token, backend, limits)
        blobs = {sha: shipped[sha] for sha in job.bundle.fmu_hashes()}
        futures[client.submit(task, job, blobs, retries=2, pure=False,
                              key=f"run-{token}-{run['run_id']}")] = run
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=len(todo), desc=spec.name, unit="run", file=sys.stderr,
                   disable=None)                # None: only on a terminal
    watch = _WorkerWatch(client, no_worker_timeout)
    try:
        for future in _as_completed(list(futures), watch):
            try:
                row = watch.result(future)
            except NoWorkers:
                raise
            except Exception as error:      # the worker died on every retry
                row = {**blank_row(futures[future], f"{type(error).__name__}: {error}"),
                       "backend": backend}
            journal.add({**row, "command": spec.replay(futures[future])})
            del futures[future]
            future.release()                # done: nothing to recompute if a worker dies
            if bar is not None:
                bar.update()
    except NoWorkers:
        client.cancel([*futures, *shipped.values()])
        raise
    finally:
        if bar is not None:
            bar.close()                     # its line ended before any message


def _close(client, cluster, teardown: SweepTeardown) -> None:
    """Close the client, and the local cluster it made; on a shared cluster, free this
    sweep's FMUs on the workers first."""
    if cluster is None:
        try:
            client.unregister_worker_plugin(teardown.name)
        except Exception:                   # workers gone with Ctrl-C
            pass
    client.close()
    if cluster is not None:                 # closing its workers frees everything
        cluster.close()


@contextmanager
def _stopping(stopped: BaseException | None, journal: Journal) -> Iterator[None]:
    """Within, after the sweep stopped early (``stopped``): logging is silenced (distributed's
    of the teardown: runs cancelled, workers lost), so the user reads only our
    message; after Ctrl-C or SIGTERM, a second signal ends the process at once, saying
    what the journal keeps (``StopSignals``)."""
    if stopped is None:
        yield
        return
    level = logging.root.manager.disable         # distributed's loggers set their own levels
    logging.disable(logging.CRITICAL)
    try:
        if isinstance(stopped, Interrupted):
            with StopSignals() as again:
                again.received = stopped.signal         # the next one is the second
                again.keep(lambda: f"{journal.path} keeps every run done "
                                   f"({len(journal.rows)})")
                yield
        else:
            yield
    finally:
        logging.disable(level)
