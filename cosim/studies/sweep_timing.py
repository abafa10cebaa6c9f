"""The sweep benchmark (``python -m cosim.bench sweep``): every backend side by side, the batch
route's campaign and memory, on fresh local clusters, each goal printed beside its figure."""
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
from .timing import in_fresh_process, load, machine, peak_rss_mb, require

SEAS = {"waves": ("waves_pd", "waves_smc"), "calm": ("calm_pd", "calm_smc")}
GOALS = {"waves": 5.0, "calm": 10.0}   # batch runs/s per core over the in-process route's
# the campaign's goal: these runs of this stop time on these workers within this many s
CAMPAIGN_RUNS, CAMPAIGN_STOP_TIME, CAMPAIGN_WORKERS, CAMPAIGN_GOAL = 1000, 400.0, 2, 30.0
MEMORY_MEMBERS = (64, 256, 1024, 4096)
MEMORY_STOP_TIME = 40.0
FLAT = 0.10     # flat: the largest sweep's peak within this of the smallest's as large batches
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
        spec = bench_spec(SEAS[sea], 2, 1.0)
        require("in-process backend", spec.backend_notes("inprocess"))
        require_batch(spec)
    measured: dict[tuple[str, str, int], list[float]] = {}
    for _ in range(rounds):
        for workers in WORKERS:                   # backends side by side, under the same load
            for sea in seas:
                for backend in SWEEP_BACKENDS:
                    m = timed_sweep(bench_spec(SEAS[sea], batch_runs if backend == BATCH
                                               else runs, stop_time), workers, backend)
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
    measure = timed_sweep(bench_spec(("waves_pd",), runs, stop_time), workers, BATCH)
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


def bench_spec(scenarios: tuple[str, ...], runs: int, stop_time: float) -> Spec:
    """``runs`` runs, an equal share for each of ``scenarios`` (as pd, smc): over wave seeds
    from 1, or in calm water (where the seed changes nothing) over headings 1 mrad apart."""
    share = runs // len(scenarios)
    axes = ({"ship.psi0": [k / 1000 for k in range(share)]} if scenarios[0].startswith("calm")
            else {"wave_seed": list(range(1, share + 1))})
    return Spec(name="bench", axes=axes, stop_time=stop_time, controllers={
        name: controller_entry(scenario, Path.cwd(), name)
        for name, scenario in zip(("pd", "smc"), scenarios)})


def require_batch(spec: Spec) -> None:
    """``require`` that every run of ``spec`` runs in batches; prints the self-test's time."""
    from ..ensemble import selftest

    first, started = selftest.cache_info().currsize == 0, time.perf_counter()
    refusal = selftest()
    require("batch route", spec.backend_notes(BATCH) + ([refusal] if refusal else []))
    if first:
        print(f"  the batch route's self-test: {time.perf_counter() - started:.1f} s, once "
              "per worker process (within each batch sweep's time)")


def timed_sweep(spec: Spec, workers: int, backend: str, batch_size: int | None = None
                ) -> Measure:
    """``spec`` on a fresh local cluster; RuntimeError if a run failed or left its batch."""
    from dask.distributed import Client

    from .campaign import execute
    from .cluster import local_cluster

    if backend == BATCH:
        require_batch(spec)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp, local_cluster(workers) as cluster:
        ready = time.perf_counter()
        rows = execute(spec, Path(tmp), scheduler=cluster.scheduler_address,
                       progress=False, backend=backend, batch_size=batch_size)
        done = time.perf_counter()
        with Client(cluster) as client:
            peaks = tuple(sorted(client.run(peak_rss_mb).values()))
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


def batch_memory(members: tuple[int, ...] = MEMORY_MEMBERS,
                 stop_time: float = MEMORY_STOP_TIME, batch_size: int | None = None) -> dict:
    """Peak memory (MB) of waves_pd runs on the batch route: of ``simulate_members`` in a
    fresh process, and of a one-worker sweep's worker, for each number of ``members``."""
    print(f"batch route memory: waves_pd runs of {stop_time:g} s, on {machine()}")
    calls = {}
    for m in members:
        wall, before, peak, results = calls[m] = in_fresh_process(
            f"simulate_members of {m} members", members_call, m, stop_time)
        rest = peak - before - results
        print(f"  simulate_members, {m:5} members: {wall:6.1f} s, peak RSS {peak:7.1f} MB, "
              f"{peak - before:7.1f} MB over the process before the call: results "
              f"{results:6.1f} MB, the rest {rest:6.1f} MB ({rest / m * 1024:5.1f} kB a member)")
    sweeps = {}
    for m in members:
        s = sweeps[m] = timed_sweep(bench_spec(("waves_pd",), m, stop_time), 1, BATCH, batch_size)
        print(f"  sweep of {m:5} runs, 1 worker, {len(s.batches):3} batch"
              f"{'es' if len(s.batches) > 1 else '  '} of {sizes(s.batches):9}: worker peak "
              f"RSS {s.peak_rss[0]:7.1f} MB ({s.wall:6.1f} s)")
    largest = max(max(s.batches) for s in sweeps.values())
    full = [m for m in members if max(sweeps[m].batches) == largest]
    if len(full) < 2:
        print(f"  memory in the sweep's size: not judged (it takes two sweeps whose batches "
              f"are of {largest} runs, the largest here)")
    else:
        low, high = sweeps[min(full)].peak_rss[0], sweeps[max(full)].peak_rss[0]
        growth = high / low - 1.0
        print(f"  goal: memory flat in the sweep's size (batches of at most {largest} runs): "
              f"worker peak RSS {low:.1f} MB at {min(full)} runs, {high:.1f} MB at "
              f"{max(full)} runs ({growth:+.1%}; flat: within {FLAT:.0%}): "
              f"{verdict(growth <= FLAT)}")
    print(f"  {load()}")
    return {"calls": calls, "sweeps": sweeps}


def members_call(members: int, stop_time: float) -> tuple[float, float, float, float]:
    """(wall s, MB: peak RSS before, peak RSS, results) of ``members`` waves_pd members."""
    from .. import scenarios
    from ..ensemble import selftest, simulate_members

    system = scenarios.load("waves_pd")
    selftest()
    before, started = peak_rss_mb(), time.perf_counter()
    recordings = simulate_members(system, [{"ship": {"wave_seed": seed}}
                                           for seed in range(1, members + 1)], stop_time)
    wall = time.perf_counter() - started
    alone = [r.meta["notes"] for r in recordings if r.meta["backend"] != "batch"]
    if alone:
        raise RuntimeError(f"{len(alone)} members ran alone: {alone[0]}")
    results = sum(r.data.nbytes for r in recordings) + recordings[0].t.nbytes
    return wall, before, peak_rss_mb(), results / 2**20
