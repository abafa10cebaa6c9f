"""Benchmarks that print figures (no timed assertions in the tests).

    python -m cosim.bench sweep [--runs 16]   runs per second of a sweep, 1 and 2 workers
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path


def machine() -> str:
    """One line on the machine the figures come from."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"{platform.system()} {platform.release()}")


def sweep_throughput(runs: int, worker_counts: tuple[int, ...] = (1, 2)) -> None:
    """Runs per second of a waves_pd/waves_smc seed sweep (400 s each) on a local cluster."""
    from dask.distributed import Client, LocalCluster

    from .sweep import Spec, execute

    print(f"sweep throughput: {runs} runs of 400 s (waves_pd and waves_smc, wave seeds), "
          f"on {machine()}")
    for workers in worker_counts:
        with tempfile.TemporaryDirectory() as tmp:
            spec_path = Path(tmp) / "bench.toml"
            spec_path.write_text(f'name = "bench"\n[axes]\n'
                                 f'wave_seed = {{ start = 1, count = {runs // 2} }}\n')
            spec = Spec.read(spec_path)
            started = time.perf_counter()
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                   dashboard_address=None, silence_logs=40)
            client = Client(cluster)
            ready = time.perf_counter()
            try:
                client.close()              # execute() opens its own client on this cluster
                rows = execute(spec, Path(tmp), scheduler=cluster.scheduler_address,
                               progress=False)
            finally:
                cluster.close()
            done = time.perf_counter()
        ok = sum(r["status"] == "ok" for r in rows)
        print(f"  {workers} worker{'s' if workers > 1 else ' '}: {ok / (done - ready):5.2f} runs/s "
              f"({ok} runs in {done - ready:5.1f} s; cluster start-up {ready - started:4.1f} s)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.bench", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    sweep = commands.add_parser("sweep", help="runs per second of a sweep with 1 and 2 workers")
    sweep.add_argument("--runs", type=int, default=16, help="runs per measurement (even)")
    args = parser.parse_args(argv)
    if args.command == "sweep":
        sweep_throughput(args.runs)
    return 0


if __name__ == "__main__":
    # Dask pickles tasks by reference to their module: import them as cosim.*, not __main__.
    from cosim.bench import main as _main
    sys.exit(_main())
