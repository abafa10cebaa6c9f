"""A sweep's client side: its runs submitted to a Dask cluster, each row journaled as it
completes, and the cluster watched for workers that run other code, or none at all.

On the batch backend the runs of each system and stop time go in batches (``plan``,
``batches``), one task each; a batch whose worker died on every retry has its runs
submitted again one per task, so that only a run that kills its worker fails.
``sweep_task`` is the other side: what a worker runs.
"""
from __future__ import annotations

import logging
import math
import queue
import sys
import time
import uuid
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Iterator

from fmukit.timebase import step_count

from ..core.interrupt import Interrupted, StopSignals
from ..provenance import PACKAGE, code_version
from ..core.watchdog import Limits
from ..ensemble import SIGNALS
from .bundle import UnsafeCache, fmu_cache
from .journal import Journal
from .sweep_spec import Spec
from .sweep_task import (BATCH, Job, SweepTeardown, batch_refusal, blank_row, fmu_bytes, noted,
                         run_batch, worker_facts)


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


class _Completions:
    """Futures as they complete, from their done callbacks (run by the future's own client,
    not the newest one); more may be added while they are taken. While none completes,
    the watch is checked. Dask's ``as_completed`` cannot do this: its timeout is a deadline
    for the whole iteration."""

    def __init__(self) -> None:
        self.done: queue.SimpleQueue = queue.SimpleQueue()
        self.waiting = 0

    def add(self, future) -> None:
        self.waiting += 1
        future.add_done_callback(self.done.put)

    def each(self, watch: _WorkerWatch) -> Iterator:
        """Each future added, before or while iterating, as it completes."""
        while self.waiting:
            try:
                future = self.done.get(timeout=watch.interval)
            except queue.Empty:
                watch.check()
                continue
            self.waiting -= 1
            yield future


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


MAX_BATCH = 1024
"""The most runs a batch gets unless told otherwise (``--batch-size``): in calm water a
step's cost is mostly numpy's per call, shared by the runs (1.2 us a run-step at 256 runs,
0.6 at 1024)."""
BATCH_MEMORY = 128 << 20
"""Bytes a batch's recorded signals may take on its worker (the figures of merit need every
sample): a batch of 400 s runs holds at most 698 runs."""
MIN_BATCH = 32
"""The fewest runs a batch is cut down to for keeping workers busy (``batch_counts``)."""
WAVES_SHARE = 128
"""The fewest runs a batch in waves is cut down to for giving every worker a share of its
system (``batch_counts``): at 128 runs the shared cost of a step is about a quarter of it."""


def batch_limit(job: Job) -> int:
    """The most runs a batch of ``job``'s system and stop time gets by default:
    ``MAX_BATCH``, or as many as ``BATCH_MEMORY`` holds the recorded signals of."""
    system = job.bundle.system
    stop = system.stop_time if job.stop_time is None else job.stop_time
    rows = step_count(system.start_time, stop, system.step_size) + 1
    return max(1, min(MAX_BATCH, BATCH_MEMORY // (len(SIGNALS) * 8 * rows)))


def batches(jobs: list[Job], workers: int, size: int | None = None) -> list[list[Job]]:
    """``jobs`` (of one system and stop time) cut into batches as ``plan`` cuts a sweep of
    them alone."""
    return _cut(jobs, batch_counts([jobs], workers, size)[0])


def batch_counts(groups: list[list[Job]], workers: int, size: int | None = None) -> list[int]:
    """How many batches each group (runs of one system and stop time) is cut into: with
    ``size``, as many as hold at most ``size`` runs each; by default, as few as its
    ``batch_limit`` allows, and in waves one per worker where they keep ``WAVES_SHARE``
    runs; then, while the sweep has fewer batches than ``workers``, the group with the
    largest batches gets one batch more, as long as its batches keep ``MIN_BATCH`` runs.

    A batch's cost per step is partly shared by its runs (numpy's cost per call, about
    0.5 ms a step) and partly each run's own. In calm water the shared part is most of it,
    and the runs of one controller cost about what another's do: there batches are made no
    smaller than keeping every worker busy needs. In waves each run's own part (the sines
    of the wave loads) is most of it, and it differs between controllers (a waves_pd run
    costs 1.4 times a waves_smc run): a system there gives every worker a share, so that
    none waits at the end for another's costlier batch."""
    if size:
        return [math.ceil(len(group) / size) for group in groups]
    counts = [math.ceil(len(group) / batch_limit(group[0])) for group in groups]
    counts = [max(count, min(workers, len(group) // WAVES_SHARE)) if _in_waves(group[0])
              else count for count, group in zip(counts, groups)]
    while sum(counts) < workers:
        largest = max(range(len(groups)), key=lambda g: len(groups[g]) / counts[g])
        if len(groups[largest]) // (counts[largest] + 1) < MIN_BATCH:
            break
        counts[largest] += 1
    return counts


def _in_waves(job: Job) -> bool:
    """Whether ``job``'s ship sails in waves (ship.Hs > 0, as set or as its system binds it)."""
    ship = job.bundle.system.parameters(job.overrides).get("ship", {})
    return float(ship.get("Hs", 0.0)) > 0.0


def _cut(jobs: list[Job], count: int) -> list[list[Job]]:
    """``jobs`` in ``count`` batches of near-equal size, in their order."""
    cuts = [round(k * len(jobs) / count) for k in range(count + 1)]
    return [jobs[a:b] for a, b in zip(cuts, cuts[1:])]


def plan(spec: Spec, jobs: list[Job], workers: int, size: int | None = None
         ) -> tuple[list[list[Job]], list[Job]]:
    """(the batches, the runs to run alone) of a sweep on the batch backend: the runs of
    each system (``Bundle.digest``) and stop time cut into batches of at most ``size`` runs
    or by default as ``batch_counts`` says, those of a controller the kernel does not cover
    (``Spec.batch_coverage``) one by one."""
    covered = spec.batch_coverage()
    groups: dict[tuple[str, float | None], list[Job]] = {}
    alone = []
    for job in jobs:
        if covered[job.run["controller"]] is None:
            groups.setdefault((job.bundle.digest, job.stop_time), []).append(job)
        else:
            alone.append(job)
    cut = list(groups.values())
    counts = batch_counts(cut, workers, size)
    return [batch for group, count in zip(cut, counts) for batch in _cut(group, count)], alone


def run_on_cluster(spec: Spec, todo: list[dict], journal: Journal, connection, progress: bool,
                   task, backend: str, no_worker_timeout: float, limits: Limits,
                   batch_task=run_batch, batch_size: int | None = None) -> None:
    """Run ``todo`` (runs of ``spec``) as ``task`` on the cluster of ``connection`` (a
    client and the local cluster it made, or None), journaling each row as it completes;
    on the batch backend, in batches as ``batch_task``; the client, and a local cluster,
    closed on every path (``execute`` documents the rest). When the sweep stops early, the
    cluster closes quietly (``_stopping``)."""
    client, cluster = connection
    teardown = SweepTeardown(uuid.uuid4().hex[:12])
    stopped = None
    try:
        _submit_and_journal(spec, todo, journal, client, progress, task, backend,
                            no_worker_timeout, limits, teardown, batch_task, batch_size)
    except BaseException as error:
        stopped = error
        raise
    finally:
        with _stopping(stopped, journal):
            _close(client, cluster, teardown)


@dataclass
class _Task:
    """What a future computes: one run, or a batch of runs."""
    jobs: list[Job]
    batch: bool
    why: str = ""                       # why its run is not in a batch (said in its backend)


def _submit_and_journal(spec: Spec, todo: list[dict], journal: Journal, client, progress: bool,
                        task, backend: str, no_worker_timeout: float, limits: Limits,
                        teardown: SweepTeardown, batch_task, batch_size: int | None) -> None:
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
    tasks: dict = {}
    completions = _Completions()

    def submit(jobs: list[Job], batch: bool, why: str = "") -> None:
        blobs = {sha: shipped[sha] for sha in jobs[0].bundle.fmu_hashes()}
        kind, what = ("batch", batch_task) if batch else ("run", task)
        future = client.submit(what, jobs if batch else jobs[0], blobs, retries=2, pure=False,
                               key=f"{kind}-{token}-{jobs[0].run['run_id']}")
        tasks[future] = _Task(jobs, batch, why)
        completions.add(future)

    route = "inprocess" if backend == BATCH else backend      # a batch's runs alone: in-process
    jobs = [spec.job(run, token, route, limits) for run in todo]
    if backend == BATCH:
        together, alone = plan(spec, jobs, sum(client.nthreads().values()) or 1, batch_size)
        if together:
            _say_batch_refusals(client)
        for batch in together:
            submit(batch, True)
        for job in alone:
            submit([job], False)
    else:
        for job in jobs:
            submit([job], False)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=len(todo), desc=spec.name, unit="run", file=sys.stderr,
                   disable=None)                # None: only on a terminal
    watch = _WorkerWatch(client, no_worker_timeout)
    try:
        for future in completions.each(watch):
            done = tasks.pop(future)
            try:
                result = watch.result(future)
            except NoWorkers:
                raise
            except Exception as error:      # the worker died on every retry
                died = f"{type(error).__name__}: {error}"
                if done.batch:              # each run alone: only a run that kills fails
                    future.release()
                    for job in done.jobs:
                        submit([job], False, f"its batch's worker died, {died}")
                    continue
                result = {**blank_row(done.jobs[0].run, died), "backend": done.jobs[0].backend}
            rows = result if done.batch else [result]
            for job, row in zip(done.jobs, rows, strict=True):
                journal.add({**(noted(row, done.why) if done.why else row),
                             "command": spec.replay(job.run)})
            future.release()                # done: nothing to recompute if a worker dies
            if bar is not None:
                bar.update(len(rows))
    except NoWorkers:
        client.cancel([*tasks, *shipped.values()])
        raise
    finally:
        if bar is not None:
            bar.close()                     # its line ended before any message


def _say_batch_refusals(client) -> None:
    """A note for each reason a worker gives to refuse the batch route (``batch_refusal``),
    once, naming the workers that give it."""
    try:
        refusals = client.run(batch_refusal, on_error="return")
    except Exception:                       # a worker gone: its runs' rows will say
        return
    said: dict[str, list[str]] = {}
    for address, reason in sorted(refusals.items()):
        if reason is not None:
            said.setdefault(str(reason), []).append(address)
    for reason, addresses in said.items():
        _say(f"note: the batch route is refused on {len(addresses)} worker"
                 f"{'s' if len(addresses) > 1 else ''} ({', '.join(addresses)}): {reason}; "
                 "their batches run one run at a time on the in-process route")


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
