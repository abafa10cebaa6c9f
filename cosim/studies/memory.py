"""The memory benchmarks: a long run streamed to disk (``bench memory``) and the batch route's
against its members and the sweep's size (``bench sweep --parts memory``), in fresh processes."""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

from ..core.master import RUN_BACKENDS
from . import in_child
from .sweep_task import BATCH
from .sweep_timing import bench_spec, require_batch, sizes, timed_sweep, verdict
from .timing import load, machine, peak_rss_mb

MEMORY_MEMBERS = (64, 256, 1024, 4096)
MEMORY_STOP_TIME = 40.0
FLAT = 0.10     # flat: the largest sweep's peak within this of the smallest's as large batches


def memory(hours: float) -> None:
    """Peak RSS of a long calm_pd run streamed to disk against a short one's, each backend."""
    print(f"Memory: calm_pd streamed to CSV in chunks of 10,000 rows, on {machine()}")
    for backend in RUN_BACKENDS:
        for duration in (3600.0, hours * 3600.0):
            rows, wall, size, peak = _in_child(f"calm_pd on {backend}", "streamed_run",
                                               backend, duration)
            print(f"  {backend:9} {duration / 3600:5.1f} h simulated: {rows:>8.0f} rows, "
                  f"{wall:6.1f} s wall, CSV {size / 1e6:7.1f} MB, peak RSS {peak:6.1f} MB")


def streamed_run(backend: str, duration: float) -> tuple[int, float, int, float]:
    """(rows, wall s, CSV bytes, peak RSS MB) of calm_pd to ``duration`` streamed to disk."""
    from .. import scenarios
    from ..core.master import Master

    with tempfile.TemporaryDirectory() as tmp, \
            Master(scenarios.load("calm_pd"), backend=backend) as master:
        started = time.perf_counter()
        recording = master.run(duration, csv_path=Path(tmp) / "run.csv")
        wall = time.perf_counter() - started
        if recording.error:
            raise RuntimeError(recording.error)
        return recording.rows, wall, recording.path.stat().st_size, peak_rss_mb()


def batch_memory(members: tuple[int, ...] = MEMORY_MEMBERS,
                 stop_time: float = MEMORY_STOP_TIME, batch_size: int | None = None) -> dict:
    """Peak memory (MB) of waves_pd runs on the batch route: of ``simulate_members`` in a
    fresh process, and of a one-worker sweep's worker, for each number of ``members``."""
    print(f"batch route memory: waves_pd runs of {stop_time:g} s, on {machine()}")
    calls = {}
    for m in members:
        wall, before, peak, results = calls[m] = _in_child(f"simulate_members of {m} members",
                                                           "members_call", m, stop_time)
        rest = peak - before - results
        print(f"  simulate_members, {m:5} members: {wall:6.1f} s, peak RSS {peak:7.1f} MB, "
              f"{peak - before:7.1f} MB over the process before the call: results "
              f"{results:6.1f} MB, the rest {rest:6.1f} MB ({rest / m * 1024:5.1f} kB a member)")
    sweeps = {}
    for m in members:
        spec = bench_spec(("waves_pd",), m, stop_time)
        require_batch(spec)
        s = sweeps[m] = timed_sweep(spec, 1, BATCH, batch_size)
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
    """(wall s, peak RSS before the call, peak RSS, results; MB) of ``simulate_members`` of
    ``members`` waves_pd runs; RuntimeError if one ran alone."""
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


def _in_child(what: str, function: str, *args: object) -> list[float]:
    """``function(*args)`` of this module in a fresh process (its own peak memory)."""
    code = f"from cosim.studies.memory import {function}; print(*{function}(*{args!r}))"
    return [float(value) for value in in_child(what, code).split()]
