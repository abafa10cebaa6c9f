"""The sweep benchmark (``python -m cosim.bench sweep``): runs per second of a seed sweep
on a local cluster, for each backend with 1 and 2 workers."""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

from ..core.master import RUN_BACKENDS
from .bench import machine, require_in_process


def sweep_throughput(runs: int, worker_counts: tuple[int, ...] = (1, 2),
                     backends: tuple[str, ...] = RUN_BACKENDS) -> dict:
    """Runs per second of a waves_pd/waves_smc seed sweep (400 s each) on a local cluster,
    for each backend and number of workers; the scaling from one worker to more, the
    overhead per run (in the task: its wall time minus the master's run; outside it:
    worker time per run minus task time), and each backend's throughput against FMI's."""
    print(f"sweep throughput: {runs} runs of 400 s (waves_pd and waves_smc, wave seeds), "
          f"on {machine()}")
    if "inprocess" in backends:                   # before minutes of measuring the others
        with tempfile.TemporaryDirectory() as tmp:
            require_in_process(_bench_spec(runs, Path(tmp)).backend_notes("inprocess"))
    rates = {}
    for workers in worker_counts:                 # backends side by side, under the same load
        for backend in backends:
            rates[backend, workers] = _sweep_rate(runs, workers, backend)
    base = min(worker_counts)
    for backend in backends:
        for workers in worker_counts:
            if workers != base:
                gain = rates[backend, workers] / rates[backend, base]
                print(f"  {backend:9}: scaling {base} -> {workers} workers: {gain:4.2f}x, parallel "
                      f"efficiency {gain / (workers / base):4.2f} (1.00: each worker as fast "
                      "as one alone)")
    for backend in backends:
        if backend != "fmi" and "fmi" in backends:
            print("  " + ", ".join(f"{backend} / fmi with {w} worker{'s' if w > 1 else ''}: "
                                   f"{rates[backend, w] / rates['fmi', w]:4.2f}x"
                                   for w in worker_counts))
    return rates


def _bench_spec(runs: int, folder: Path):
    """The benchmark's sweep: waves_pd and waves_smc over runs / 2 wave seeds."""
    from .sweep_spec import Spec

    spec_path = folder / "bench.toml"
    spec_path.write_text('name = "bench"\n[axes]\n'
                         f'wave_seed = {{ start = 1, count = {runs // 2} }}\n')
    return Spec.read(spec_path)


def _sweep_rate(runs: int, workers: int, backend: str) -> float:
    from dask.distributed import Client

    from .cluster import local_cluster
    from .sweep import execute

    with tempfile.TemporaryDirectory() as tmp:
        spec = _bench_spec(runs, Path(tmp))
        started = time.perf_counter()
        cluster = local_cluster(workers)
        Client(cluster).close()
        ready = time.perf_counter()
        try:
            rows = execute(spec, Path(tmp), scheduler=cluster.scheduler_address,
                           progress=False, backend=backend)
        finally:
            cluster.close()
        done = time.perf_counter()
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok:
        raise RuntimeError(f"no run of the {backend} sweep succeeded: {rows[0]['error']}")
    wall = done - ready
    simulated = sum(r["sim_seconds"] for r in ok) / len(ok)
    in_task = sum(r["seconds"] - r["sim_seconds"] for r in ok) / len(ok)
    outside = wall * workers / len(ok) - simulated - in_task
    print(f"  {backend:9} {workers} worker{'s' if workers > 1 else ' '}: {len(ok) / wall:5.2f} "
          f"runs/s ({len(ok)} runs in {wall:5.1f} s; cluster start-up {ready - started:4.1f} s); "
          f"per run: simulation {simulated:5.3f} s, overhead in the task {in_task:5.3f} s "
          f"({in_task / simulated:4.1%}), outside it {outside:5.3f} s "
          f"({outside / simulated:4.1%})")
    return len(ok) / wall
