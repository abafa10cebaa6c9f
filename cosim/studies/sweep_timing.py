"""The sweep benchmark (``python -m cosim.bench sweep``): sweeps on a local cluster, every
backend side by side, and the batch route's goals (issue 29), each printed beside its figure.

- ``sweep_throughput``: runs per second of sweeps of 400 s runs (waves_pd and waves_smc over
  wave seeds; calm_pd and calm_smc over initial headings) on the FMI, in-process and batch
  backends with 1 and 2 workers, per core, and the batch route's against the in-process
  route's;
- ``campaign``: 1,000 waves_pd runs of 400 s on the batch route on 2 workers, from
  submission to the last row, and with the cluster's start-up;
- ``batch_memory``: the peak memory of ``simulate_members`` against its number of members,
  and of a worker against the size of the sweep it ran (cut into batches as the sweep cuts
  them, ``sweep_client.plan``).

The machines are shared: each part prints the load average before and after it.
"""
from __future__ import annotations

import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from .timing import machine, peak_rss_mb, require_in_process
from .sweep_client import plan
from .sweep_task import BATCH, SWEEP_BACKENDS

SEAS = {"waves": ("waves_pd", "waves_smc"), "calm": ("calm_pd", "calm_smc")}
"""The scenarios of each sea's sweeps: the paper's two autopilots."""
GOALS = {"waves": 5.0, "calm": 10.0}
"""The batch route's runs per second per core, at least this many times the in-process
route's (issue 29)."""
CAMPAIGN_RUNS, CAMPAIGN_STOP_TIME, CAMPAIGN_WORKERS, CAMPAIGN_GOAL = 1000, 400.0, 2, 30.0
"""The issue's campaign: 1,000 waves_pd runs of 400 s in under 30 s on these two cores."""
MEMORY_MEMBERS = (64, 256, 1024, 4096)
"""Members of the ``simulate_members`` calls, and runs of the sweeps, whose memory is
measured."""
MEMORY_STOP_TIME = 40.0
"""s, each run of the memory measurement (its results grow with it; nothing else does)."""
FLAT = 0.10
"""A worker's peak memory counts as flat if the largest sweep's is within this fraction of
that of the smallest sweep whose batches are as large."""


def load() -> str:
    """The load average, as printed beside the figures."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} (1, 5, 15 min)"


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
    def rate(self) -> float:
        """Runs per second."""
        return self.runs / self.wall

    @property
    def outside(self) -> float:
        """s per run of worker time outside the tasks."""
        return self.wall * self.workers / self.runs - self.simulated - self.in_task


def sweep_throughput(runs: int = 32, batch_runs: int = 1024,
                     seas: tuple[str, ...] = tuple(SEAS), worker_counts: tuple[int, ...] = (1, 2),
                     backends: tuple[str, ...] = SWEEP_BACKENDS, rounds: int = 1,
                     stop_time: float = 400.0) -> dict[tuple[str, str, int], float]:
    """Runs per second, (sea, backend, workers): the median of ``rounds`` sweeps of ``runs``
    runs (``batch_runs`` on the batch backend), measured in turn, round after round; printed
    with the per-core rates, the parallel efficiency and the batch route's goals (judged by
    the median of the rounds' ratios, each of a batch sweep to the in-process sweep of its
    round)."""
    _check_runs(runs, "runs")
    _check_runs(batch_runs, "batch_runs")
    if rounds < 1:
        raise ValueError(f"rounds must be at least 1, got {rounds}")
    print(f"sweep throughput: runs of {stop_time:g} s (waves: {' and '.join(SEAS['waves'])} "
          f"over wave seeds; calm: {' and '.join(SEAS['calm'])} over initial headings), "
          f"{runs} runs a sweep ({batch_runs} on the batch backend), each on a fresh local "
          f"cluster, on {machine()}; {load()}")
    for sea in seas:                              # before minutes of measuring the others
        _require(sea, backends)
    measured: dict[tuple[str, str, int], list[float]] = {}
    for _ in range(rounds):
        for workers in worker_counts:             # backends side by side, under the same load
            for sea in seas:
                for backend in backends:
                    measure = _sea_sweep(sea, batch_runs if backend == BATCH else runs,
                                         workers, backend, stop_time)
                    _print_measure(f"{sea:5} {backend:9}", measure)
                    measured.setdefault((sea, backend, workers), []).append(measure.rate)
    rates = {key: statistics.median(values) for key, values in measured.items()}
    _print_rates(rates, seas, worker_counts, backends, rounds)
    if BATCH in backends and "inprocess" in backends:
        for sea in seas:
            _print_goal(sea, {w: [b / i for b, i in zip(measured[sea, BATCH, w],
                                                        measured[sea, "inprocess", w])]
                              for w in worker_counts})
    print(f"  {load()}")
    return rates


def campaign(runs: int = CAMPAIGN_RUNS, workers: int = CAMPAIGN_WORKERS,
             stop_time: float = CAMPAIGN_STOP_TIME) -> Measure:
    """``runs`` waves_pd runs of ``stop_time`` on the batch route on a local cluster of
    ``workers``: the wall time from submission to the last row, and with the cluster's
    start-up, against the issue's goal where it is the issue's campaign."""
    if runs < 1:
        raise ValueError(f"the campaign's runs must be at least 1, got {runs}")
    print(f"campaign: {runs} waves_pd runs of {stop_time:g} s on the batch route, a local "
          f"cluster of {_workers(workers)}, on {machine()}; {load()}")
    with tempfile.TemporaryDirectory() as tmp:
        spec = _bench_spec(Path(tmp), {"pd": "waves_pd"}, _seeds(runs), stop_time)
        _require_batch(spec)
        measure = _sweep(spec, workers, BATCH)
    total = measure.wall + measure.startup
    print(f"  {measure.runs} runs in {measure.wall:.1f} s from submission to the last row "
          f"({measure.rate:.1f} runs/s, {measure.rate / workers:.1f} per core; batches of "
          f"{_sizes(measure.batches)}); {total:.1f} s with the cluster's start-up "
          f"({measure.startup:.1f} s)")
    if (runs, stop_time, workers) == (CAMPAIGN_RUNS, CAMPAIGN_STOP_TIME, CAMPAIGN_WORKERS):
        print(f"  goal: {CAMPAIGN_RUNS:,} waves_pd runs of {CAMPAIGN_STOP_TIME:g} s in under "
              f"{CAMPAIGN_GOAL:g} s on {CAMPAIGN_WORKERS} cores: {measure.wall:.1f} s "
              f"({total:.1f} s with the start-up): {_verdict(measure.wall < CAMPAIGN_GOAL)}"
              + ("" if total < CAMPAIGN_GOAL or measure.wall >= CAMPAIGN_GOAL
                 else ", not with the start-up"))
    else:
        print(f"  (the goal is for {CAMPAIGN_RUNS:,} runs of {CAMPAIGN_STOP_TIME:g} s on "
              f"{CAMPAIGN_WORKERS} workers: not judged here)")
    print(f"  {load()}")
    return measure


def batch_memory(members: tuple[int, ...] = MEMORY_MEMBERS,
                 stop_time: float = MEMORY_STOP_TIME, batch_size: int | None = None) -> dict:
    """Peak memory (MB) of waves_pd runs of ``stop_time`` on the batch route: of a
    ``simulate_members`` call in a fresh process for each number of ``members`` (with what
    its results take), and of the one worker of a sweep of as many runs in batches of at
    most ``batch_size`` (default: the sweep's); whether the worker's is flat in the sweep's
    size."""
    print(f"batch route memory: waves_pd runs of {stop_time:g} s, on {machine()}; {load()}")
    calls = {m: _members_call(m, stop_time) for m in members}
    for m, (wall, before, peak, results) in calls.items():
        rest = peak - before - results
        print(f"  simulate_members, {m:5} members: {wall:6.1f} s, peak RSS {peak:7.1f} MB, "
              f"{peak - before:7.1f} MB over the process before the call: results "
              f"{results:6.1f} MB, the rest {rest:6.1f} MB ({rest / m * 1024:5.1f} kB a member)")
    sweeps = {}
    with tempfile.TemporaryDirectory() as tmp:
        for m in members:
            spec = _bench_spec(Path(tmp) / str(m), {"pd": "waves_pd"}, _seeds(m), stop_time)
            _require_batch(spec)
            sweeps[m] = _sweep(spec, 1, BATCH, batch_size)
            print(f"  sweep of {m:5} runs, 1 worker, {len(sweeps[m].batches):3} batch"
                  f"{'es' if len(sweeps[m].batches) > 1 else '  '} of "
                  f"{_sizes(sweeps[m].batches):9}: worker peak RSS "
                  f"{sweeps[m].peak_rss[0]:7.1f} MB ({sweeps[m].wall:6.1f} s)")
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
              f"{_verdict(growth <= FLAT)}")
    print(f"  {load()}")
    return {"calls": calls, "sweeps": sweeps}


def _check_runs(runs: int, name: str) -> None:
    if runs < 2 or runs % 2:
        raise ValueError(f"{name} must be an even number of runs >= 2 (half for each "
                         f"autopilot), got {runs}")


def _verdict(met: bool) -> str:
    return "met" if met else "NOT met"


def _workers(count: int) -> str:
    return f"{count} worker{'s' if count > 1 else ''}"


def _sizes(sizes: tuple[int, ...]) -> str:
    """Batch sizes, as "256" or "250-256"."""
    low, high = min(sizes), max(sizes)
    return f"{low}" if low == high else f"{low}-{high}"


def _seeds(runs: int) -> dict[str, str]:
    """The axis of ``runs`` wave seeds from 1, in TOML."""
    return {"wave_seed": f"{{ start = 1, count = {runs} }}"}


def _headings(runs: int) -> dict[str, str]:
    """The axis of ``runs`` initial headings 0, 1, 2, ... mrad, in TOML (in calm water the
    wave seed changes nothing)."""
    return {'"ship.psi0"': "[" + ", ".join(repr(k / 1000) for k in range(runs)) + "]"}


def _bench_spec(folder: Path, controllers: dict[str, str], axes: dict[str, str],
                stop_time: float):
    """A sweep of ``controllers`` (name: scenario) over ``axes`` (name: its TOML value)."""
    from .sweep_spec import Spec

    folder.mkdir(parents=True, exist_ok=True)
    text = (f'name = "bench"\nstop_time = {stop_time!r}\n[controllers]\n'
            + "".join(f'{name} = {{ scenario = "{scenario}" }}\n'
                      for name, scenario in controllers.items())
            + "[axes]\n" + "".join(f"{name} = {value}\n" for name, value in axes.items()))
    path = folder / "bench.toml"
    path.write_text(text)
    return Spec.read(path)


def _sea_spec(folder: Path, sea: str, runs: int, stop_time: float):
    """The sweep of ``runs`` runs of a sea: half with each of its scenarios."""
    axis = _seeds if sea == "waves" else _headings
    return _bench_spec(folder, dict(zip(("pd", "smc"), SEAS[sea])), axis(runs // 2), stop_time)


def _require(sea: str, backends: tuple[str, ...]) -> None:
    """RuntimeError if a backend of ``backends`` would not run the sea's sweeps as itself."""
    with tempfile.TemporaryDirectory() as tmp:
        spec = _sea_spec(Path(tmp), sea, 2, 1.0)
        if "inprocess" in backends:
            require_in_process(spec.backend_notes("inprocess"))
        if BATCH in backends:
            _require_batch(spec)


def _require_batch(spec) -> None:
    """RuntimeError if the runs of ``spec`` would not all run in batches (the kernel does not
    cover a system, or refuses this machine): the batch route could not be measured. Prints
    the self-test's time, which each worker process spends once."""
    from ..ensemble import selftest

    notes = spec.backend_notes(BATCH)
    first, started = selftest.cache_info().currsize == 0, time.perf_counter()
    refusal = selftest()
    if refusal:
        notes.append(refusal)
    if notes:
        raise RuntimeError("the batch route cannot be measured: " + "; ".join(notes))
    if first:
        print(f"  the batch route's self-test: {time.perf_counter() - started:.1f} s, once "
              "per worker process (within each batch sweep's time)")


def _sea_sweep(sea: str, runs: int, workers: int, backend: str, stop_time: float) -> Measure:
    with tempfile.TemporaryDirectory() as tmp:
        return _sweep(_sea_spec(Path(tmp), sea, runs, stop_time), workers, backend)


def _sweep(spec, workers: int, backend: str, batch_size: int | None = None) -> Measure:
    """``spec`` run on a fresh local cluster of ``workers``; RuntimeError if a run failed,
    or, on the batch backend, ran other than in a batch."""
    from dask.distributed import Client

    from .cluster import local_cluster
    from .campaign import execute

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
    if backend == BATCH:
        alone = [r for r in rows if r["backend"] != BATCH]
        if alone:
            raise RuntimeError(f"{len(alone)} of {len(rows)} runs of the batch sweep ran "
                               f"alone: {alone[0]['backend']}")
    sizes = tuple(len(b) for b in plan(spec, [spec.job(g[0], "bench", "inprocess")
                                              for g in spec.shared_runs()],
                                       workers, batch_size)[0]) if backend == BATCH else ()
    simulated = math.fsum(r["sim_seconds"] for r in rows) / len(rows)
    in_task = math.fsum(r["seconds"] - r["sim_seconds"] for r in rows) / len(rows)
    return Measure(len(rows), workers, done - ready, ready - started, simulated, in_task,
                   sizes, peaks, os.getloadavg()[0])


def _members_call(members: int, stop_time: float) -> tuple[float, float, float, float]:
    """(wall s, peak RSS before the call MB, peak RSS MB, results MB) of ``simulate_members``
    of ``members`` waves_pd runs of ``stop_time`` (wave seeds 1, 2, ...) in a fresh process;
    RuntimeError if a member did not run in the batch."""
    code = ("import sys, time\n"
            "from cosim import scenarios\n"
            "from cosim.ensemble import selftest, simulate_members\n"
            "from cosim.studies.timing import peak_rss_mb\n"
            "system = scenarios.load('waves_pd')\n"
            "selftest()\n"
            "before = peak_rss_mb()\n"
            "started = time.perf_counter()\n"
            f"recordings = simulate_members(system, [{{'ship': {{'wave_seed': seed}}}} "
            f"for seed in range(1, {members + 1})], {stop_time!r})\n"
            "wall = time.perf_counter() - started\n"
            "alone = [r.meta['notes'] for r in recordings if r.meta['backend'] != 'batch']\n"
            "if alone:\n"
            "    sys.exit(f'{len(alone)} members ran alone: {alone[0]}')\n"
            "print(wall, before, peak_rss_mb(),\n"
            "      sum(r.data.nbytes for r in recordings) + recordings[0].t.nbytes)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=False)
    if done.returncode:
        raise RuntimeError(f"simulate_members of {members} members failed: "
                           f"{done.stderr.strip().splitlines()[-1:]}")
    wall, before, peak, results = map(float, done.stdout.split())
    return wall, before, peak, results / 2**20


def _print_measure(label: str, m: Measure) -> None:
    batched = f"; batches of {_sizes(m.batches)}" if m.batches else ""
    print(f"  {label} {m.workers} worker{'s' if m.workers > 1 else ' '}: {m.rate:6.2f} runs/s "
          f"({m.runs} runs in {m.wall:5.1f} s; cluster start-up {m.startup:4.1f} s{batched}); "
          f"per run: simulation {m.simulated:5.3f} s, overhead in the task {m.in_task:5.3f} s "
          f"({m.in_task / m.simulated:4.1%}), outside it {m.outside:5.3f} s "
          f"({m.outside / m.simulated:4.1%}); load {m.load:.2f}")


def _efficiency(rates: dict[tuple[str, str, int], float], sea: str, backend: str, base: int,
                workers: int) -> float:
    """The parallel efficiency from ``base`` workers to ``workers``: 1.0 if each worker runs
    as fast as one of ``base`` alone."""
    return rates[sea, backend, workers] / rates[sea, backend, base] / (workers / base)


def _print_rates(rates: dict[tuple[str, str, int], float], seas: tuple[str, ...],
                 worker_counts: tuple[int, ...], backends: tuple[str, ...], rounds: int) -> None:
    """Per-core rates and parallel efficiency, the ratios between backends and the goals."""
    base = min(worker_counts)
    others = [w for w in worker_counts if w != base]
    print("  runs/s per core (runs/s / workers" + (f", median of {rounds} rounds" if rounds > 1
                                                 else "") + "):")
    print(f"    {'':15}" + "".join(f"{_workers(w):>11}" for w in worker_counts)
          + "".join(f"{f'efficiency {base}->{w}':>17}" for w in others))
    for sea in seas:
        for backend in backends:
            print(f"    {sea:5} {backend:9}"
                  + "".join(f"{rates[sea, backend, w] / w:11.2f}" for w in worker_counts)
                  + "".join(f"{_efficiency(rates, sea, backend, base, w):17.2f}"
                            for w in others))
    print("    (efficiency 1.00: each worker as fast as one alone)")
    for sea in seas:
        for backend in backends:
            if backend != "fmi" and "fmi" in backends:
                print(f"  {sea:5} {backend} / fmi: " + ", ".join(
                    f"{rates[sea, backend, w] / rates[sea, 'fmi', w]:5.2f}x with {_workers(w)}"
                    for w in worker_counts))


def _print_goal(sea: str, ratios: dict[int, list[float]]) -> None:
    """The batch route's goal in ``sea``: for each number of workers, the batch sweep's
    rate over the in-process sweep's of the same round (the same per core), the median of
    the rounds, each round's beside it."""
    medians = {w: statistics.median(r) for w, r in ratios.items()}
    print(f"  goal, {sea}: batch runs/s per core at least {GOALS[sea]:g}x in-process: "
          + ", ".join(f"{medians[w]:.2f}x with {_workers(w)}"
                      + (f" (rounds: {', '.join(f'{x:.2f}' for x in r)})" if len(r) > 1 else "")
                      for w, r in ratios.items())
          + f": {_verdict(all(m >= GOALS[sea] for m in medians.values()))}")
