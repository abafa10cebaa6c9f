"""The memory benchmarks: a long run streamed to disk (``python -m cosim.bench memory``), and
the batch route's memory against its members and the sweep's size (``bench sweep --parts
memory``)."""
from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from ..core.master import RUN_BACKENDS
from .sweep_task import BATCH
from .sweep_timing import bench_spec, load, require_batch, seeds, sizes, timed_sweep, verdict
from .timing import machine

MEMORY_MEMBERS = (64, 256, 1024, 4096)
MEMORY_STOP_TIME = 40.0
FLAT = 0.10
"""A worker's peak memory is flat if the largest sweep's is within this fraction of that of
the smallest sweep whose batches are as large."""


def memory(hours: float, backends: tuple[str, ...] = RUN_BACKENDS) -> None:
    """A long calm_pd run with rows streamed to disk; peak RSS against a short run, for each
    backend."""
    print(f"Memory: calm_pd streamed to CSV in chunks of 10,000 rows, on {machine()}")
    for backend, duration in ((b, d) for b in backends for d in (3600.0, hours * 3600.0)):
        code = ("import time, tempfile, os\n"
                "from cosim import scenarios\nfrom cosim.core.master import Master\n"
                "from cosim.studies.timing import peak_rss_mb\n"
                f"m = Master(scenarios.load('calm_pd'), backend={backend!r})\n"
                "out = os.path.join(tempfile.mkdtemp(), 'run.csv')\n"
                "t = time.perf_counter()\n"
                f"rec = m.run({duration!r}, csv_path=out)\n"
                "wall = time.perf_counter() - t\n"
                "m.free()\n"
                "assert rec.error is None, rec.error\n"
                "print(rec.rows, wall, os.path.getsize(out), peak_rss_mb())\n"
                "os.remove(out)\n")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True).stdout.split()
        rows, wall, size, peak = int(out[0]), float(out[1]), int(out[2]), float(out[3])
        print(f"  {backend:9} {duration / 3600:5.1f} h simulated: {rows:>8} rows, "
              f"{wall:6.1f} s wall, CSV {size / 1e6:7.1f} MB, peak RSS {peak:6.1f} MB")


def batch_memory(members: tuple[int, ...] = MEMORY_MEMBERS,
                 stop_time: float = MEMORY_STOP_TIME, batch_size: int | None = None) -> dict:
    """Peak memory (MB) of waves_pd runs on the batch route: of ``simulate_members`` in a
    fresh process for each number of ``members``, and of the one worker of a sweep of as
    many runs; whether the worker's is flat in the sweep's size."""
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
            spec = bench_spec(Path(tmp) / str(m), {"pd": "waves_pd"}, seeds(m), stop_time)
            require_batch(spec)
            sweeps[m] = timed_sweep(spec, 1, BATCH, batch_size)
            print(f"  sweep of {m:5} runs, 1 worker, {len(sweeps[m].batches):3} batch"
                  f"{'es' if len(sweeps[m].batches) > 1 else '  '} of "
                  f"{sizes(sweeps[m].batches):9}: worker peak RSS "
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
              f"{verdict(growth <= FLAT)}")
    print(f"  {load()}")
    return {"calls": calls, "sweeps": sweeps}


def _members_call(members: int, stop_time: float) -> tuple[float, float, float, float]:
    """(wall s, peak RSS before the call, peak RSS, results; MB) of ``simulate_members`` of
    ``members`` waves_pd runs in a fresh process; RuntimeError if a member ran alone."""
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
