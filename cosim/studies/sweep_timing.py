"""The sweep benchmark (``python -m cosim.bench sweep``): every backend side by side and the
batch route's campaign, each on fresh local clusters, each goal printed beside its figure."""
from __future__ import annotations

import math
import os
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from .spec_file import controller_entry
from .campaign import plan
from .sweep_spec import Spec
from .sweep_task import BATCH, SWEEP_BACKENDS
from .timing import load, machine, peak_rss_mb, require_in_process

SEAS = {"waves": ("waves_pd", "waves_smc"), "calm": ("calm_pd", "calm_smc")}
GOALS = {"waves": 5.0, "calm": 10.0}   # batch runs/s per core over the in-process route's
# the campaign's goal: these runs of this stop time on these workers within this many s
CAMPAIGN_RUNS, CAMPAIGN_STOP_TIME, CAMPAIGN_WORKERS, CAMPAIGN_GOAL = 1000, 400.0, 2, 30.0
WORKERS = (1, 2)            # the throughput's sweeps: on 1 and on 2 workers


@dataclass(frozen=True)
class Measure:
    """One sweep on a fresh local cluster."""
    runs: int                   # its runs (all succeeded)
    workers: int
    wall: float                 # s, from submission to the last row
    startup: float              # s, the cluster's start-up before it
    simulated: float            # s per run: its simulation (a batch member's: its share)
    in_task: float              # s per run: the rest of its task
    batches: tuple[int, ...]    # runs per batch (batch backend), of each system in turn
    peak_rss: tuple[float, ...]  # MB, each worker's peak memory after the sweep
    load: float                 # the 1-minute load average as it ended

    @property
    def rate(self) -> float:            # runs per second
        return self.runs / self.wall


def sweep_throughput(runs: int = 32, batch_runs: int = 1024, seas: tuple[str, ...] = tuple(SEAS),
                     rounds: int = 1, stop_time: float = 400.0
                     ) -> dict[tuple[str, str, int], float]:
    """Runs per second by (sea, backend, workers), the median of ``rounds`` sweeps taken in
    turn; printed with the per-core rates, the parallel efficiency and the goals."""
    for count, name in ((runs, "runs"), (batch_runs, "batch_runs")):
        if count < 2 or count % 2:
            raise ValueError(f"{name} must be an even number of runs >= 2 (half for each "
                             f"autopilot), got {count}")
    if rounds < 1:
        raise ValueError(f"rounds must be at least 1, got {rounds}")
    print(f"sweep throughput: runs of {stop_time:g} s (waves: {' and '.join(SEAS['waves'])} "
          f"over wave seeds; calm: {' and '.join(SEAS['calm'])} over initial headings), "
          f"{runs} runs a sweep ({batch_runs} on the batch backend), each on a fresh local "
          f"cluster, on {machine()}")
    for sea in seas:                              # before minutes of measuring the others
        spec = _sea_spec(sea, 2, 1.0)
        require_in_process(spec.backend_notes("inprocess"))
        require_batch(spec)
    measured: dict[tuple[str, str, int], list[float]] = {}
    for _ in range(rounds):
        for workers in WORKERS:                   # backends side by side, under the same load
            for sea in seas:
                for backend in SWEEP_BACKENDS:
                    m = timed_sweep(_sea_spec(sea, batch_runs if backend == BATCH else runs,
                                              stop_time), workers, backend)
                    batched = f"; batches of {sizes(m.batches)}" if m.batches else ""
                    outside = m.wall * m.workers / m.runs - m.simulated - m.in_task
                    print(f"  {sea:5} {backend:9} {_workers(workers):9}: {m.rate:6.2f} runs/s "
                          f"({m.runs} runs in {m.wall:5.1f} s; cluster start-up "
                          f"{m.startup:4.1f} s{batched}); per run: simulation "
                          f"{m.simulated:5.3f} s, overhead in the task {m.in_task:5.3f} s "
                          f"({m.in_task / m.simulated:4.1%}), outside it {outside:5.3f} s "
                          f"({outside / m.simulated:4.1%}); load {m.load:.2f}")
                    measured.setdefault((sea, backend, workers), []).append(m.rate)
    rates = {key: statistics.median(values) for key, values in measured.items()}
    print("  runs/s per core (runs/s / workers" + (f", median of {rounds} rounds" if rounds > 1
                                                 else "") + "):")
    print(f"    {'':15}" + "".join(f"{_workers(w):>11}" for w in WORKERS)
          + f"{'efficiency 1->2':>17}")
    for sea in seas:
        for backend in SWEEP_BACKENDS:
            one, two = (rates[sea, backend, w] for w in WORKERS)
            print(f"    {sea:5} {backend:9}{one:11.2f}{two / 2:11.2f}{two / one / 2:17.2f}")
    print("    (efficiency 1.00: each worker as fast as one alone)")
    for sea in seas:
        for backend in SWEEP_BACKENDS[1:]:
            print(f"  {sea:5} {backend} / fmi: " + ", ".join(
                f"{rates[sea, backend, w] / rates[sea, 'fmi', w]:5.2f}x with {_workers(w)}"
                for w in WORKERS))
    for sea in seas:
        ratios = {w: [b / i for b, i in zip(measured[sea, BATCH, w], measured[sea, "inprocess", w])]
                  for w in WORKERS}
        medians = {w: statistics.median(r) for w, r in ratios.items()}
        print(f"  goal, {sea}: batch runs/s per core at least {GOALS[sea]:g}x in-process: "
              + ", ".join(f"{medians[w]:.2f}x with {_workers(w)}" + (
                  f" (rounds: {', '.join(f'{x:.2f}' for x in r)})" if len(r) > 1 else "")
                  for w, r in ratios.items())
              + f": {verdict(all(m >= GOALS[sea] for m in medians.values()))}")
    print(f"  {load()}")
    return rates


def campaign(runs: int = CAMPAIGN_RUNS, workers: int = CAMPAIGN_WORKERS,
             stop_time: float = CAMPAIGN_STOP_TIME) -> Measure:
    """``runs`` waves_pd runs on the batch route on ``workers``, against the goal."""
    if runs < 1:
        raise ValueError(f"the campaign's runs must be at least 1, got {runs}")
    print(f"campaign: {runs} waves_pd runs of {stop_time:g} s on the batch route, a local "
          f"cluster of {_workers(workers)}, on {machine()}")
    spec = bench_spec({"pd": "waves_pd"}, seeds(runs), stop_time)
    require_batch(spec)
    measure = timed_sweep(spec, workers, BATCH)
    total = measure.wall + measure.startup
    print(f"  {measure.runs} runs in {measure.wall:.1f} s from submission to the last row "
          f"({measure.rate:.1f} runs/s, {measure.rate / workers:.1f} per core; batches of "
          f"{sizes(measure.batches)}); {total:.1f} s with the cluster's start-up "
          f"({measure.startup:.1f} s)")
    if (runs, stop_time, workers) == (CAMPAIGN_RUNS, CAMPAIGN_STOP_TIME, CAMPAIGN_WORKERS):
        print(f"  goal: {CAMPAIGN_RUNS:,} waves_pd runs of {CAMPAIGN_STOP_TIME:g} s in under "
              f"{CAMPAIGN_GOAL:g} s on {CAMPAIGN_WORKERS} cores: {measure.wall:.1f} s "
              f"({total:.1f} s with the start-up): {verdict(measure.wall < CAMPAIGN_GOAL)}"
              + ("" if total < CAMPAIGN_GOAL or measure.wall >= CAMPAIGN_GOAL
                 else ", not with the start-up"))
    else:
        print(f"  (the goal is for {CAMPAIGN_RUNS:,} runs of {CAMPAIGN_STOP_TIME:g} s on "
              f"{CAMPAIGN_WORKERS} workers: not judged here)")
    print(f"  {load()}")
    return measure


def verdict(met: bool) -> str:
    return "met" if met else "NOT met"


def _workers(count: int) -> str:
    return f"{count} worker{'s' if count > 1 else ''}"


def sizes(sizes: tuple[int, ...]) -> str:
    """Batch sizes, as "256" or "250-256"."""
    low, high = min(sizes), max(sizes)
    return f"{low}" if low == high else f"{low}-{high}"


def seeds(runs: int) -> dict[str, list]:        # the axis of ``runs`` wave seeds from 1
    return {"wave_seed": list(range(1, runs + 1))}


def bench_spec(controllers: dict[str, str], axes: dict[str, list], stop_time: float) -> Spec:
    """A sweep of ``controllers`` (name: scenario) over ``axes`` (name: its values)."""
    return Spec(name="bench", controllers={name: controller_entry(scenario, Path.cwd(), name)
                                           for name, scenario in controllers.items()},
                axes=axes, stop_time=stop_time)


def _sea_spec(sea: str, runs: int, stop_time: float) -> Spec:
    """``runs`` runs, half with each scenario of the sea: over wave seeds, or in calm water
    (where the seed changes nothing) over headings 1 mrad apart."""
    axes = seeds(runs // 2) if sea == "waves" else {
        "ship.psi0": [k / 1000 for k in range(runs // 2)]}
    return bench_spec(dict(zip(("pd", "smc"), SEAS[sea])), axes, stop_time)


def require_batch(spec: Spec) -> None:
    """RuntimeError if the runs of ``spec`` would not all run in batches; prints the
    self-test's time."""
    from ..ensemble import selftest

    notes = spec.backend_notes(BATCH)
    first, started = selftest.cache_info().currsize == 0, time.perf_counter()
    notes += [refusal] if (refusal := selftest()) else []
    if notes:
        raise RuntimeError("the batch route cannot be measured: " + "; ".join(notes))
    if first:
        print(f"  the batch route's self-test: {time.perf_counter() - started:.1f} s, once "
              "per worker process (within each batch sweep's time)")


def timed_sweep(spec: Spec, workers: int, backend: str, batch_size: int | None = None
                ) -> Measure:
    """``spec`` on a fresh local cluster; RuntimeError if a run failed or left its batch."""
    from dask.distributed import Client

    from .campaign import execute
    from .cluster import local_cluster

    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        cluster = local_cluster(workers)
        try:
            ready = time.perf_counter()
            rows = execute(spec, Path(tmp), scheduler=cluster.scheduler_address,
                           progress=False, backend=backend, batch_size=batch_size)
            done = time.perf_counter()
            with Client(cluster) as client:
                peaks = tuple(sorted(client.run(peak_rss_mb).values()))
        finally:
            cluster.close()
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        raise RuntimeError(f"{len(failed)} of {len(rows)} runs of the {backend} sweep failed: "
                           f"{failed[0]['error']}")
    alone = [r for r in rows if r["backend"] != BATCH] if backend == BATCH else []
    if alone:
        raise RuntimeError(f"{len(alone)} of {len(rows)} runs of the batch sweep ran "
                           f"alone: {alone[0]['backend']}")
    jobs = [spec.job(group[0], "bench", "inprocess") for group in spec.shared_runs()]
    batches = plan(spec, jobs, workers, batch_size)[0] if backend == BATCH else []
    return Measure(len(rows), workers, done - ready, ready - started,
                   math.fsum(r["sim_seconds"] for r in rows) / len(rows),
                   math.fsum(r["seconds"] - r["sim_seconds"] for r in rows) / len(rows),
                   tuple(map(len, batches)), peaks, os.getloadavg()[0])
