"""Benchmarks that print figures (never timed assertions); ``python -m cosim.bench`` runs them.

- ``engines``: calm_pd and waves_pd, 400 s, (a) the plain Python modules wired by
  hand in-process (``cosim.studies.direct``), (b) our master through the FMUs, (c)
  OSP libcosim and (d) ecos on the exported SSP package of the same scenario, each
  the median wall time of several runs; and the cost per step of the ship FMU's
  doStep alone and of the master's own work (the master on the null backend);
- ``memory``: a long calm_pd run streamed to CSV, peak memory against a 1 h run;
- ``sweep_throughput``: runs per second of a seed sweep on a local cluster.
"""
from __future__ import annotations

import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

STEPS = 4000
TARGETS = {"waves_pd through the FMUs": "<= 0.3 s", "b/a": "<= 1.25", "c/b": ">= 3"}


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


def median_time(run: Callable[[], object], repeats: int) -> float:
    """Median wall time of ``repeats`` calls, after one warm-up call."""
    run()
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        run()
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def _libcosim_runner(ssp: Path) -> Callable[[], None]:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)

    def run() -> None:
        execution = CosimExecution.from_ssp_file(str(ssp))
        if not execution.simulate_until(400 * 10**9):        # nanoseconds
            raise RuntimeError("libcosim failed")
    return run


def _ecos_runner(ssp: Path) -> Callable[[], None]:
    from ecospy import EcosLib, EcosSimulation

    EcosLib.set_log_level("err")

    def run() -> None:
        simulation = EcosSimulation(step_size=0.1, ssp_path=str(ssp))
        simulation.init(parameter_set="scenario")
        simulation.step(STEPS)
        simulation.terminate()
        simulation.free()
    return run


def engines(repeats: int) -> None:
    from .. import scenarios
    from ..core.master import Master
    from ..interop.ssp import export
    from .direct import run_direct

    print(f"Engines on the same system, 400 s = {STEPS} macro steps of 0.1 s, median of "
          f"{repeats} runs, on {machine()}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in ("calm_pd", "waves_pd"):
            system = scenarios.load(name)
            ssp = export(name, Path(tmp))
            master = Master(system)
            try:
                def ours() -> None:
                    master.reset()
                    if master.run().error:
                        raise RuntimeError("our master failed")
                times = {"a": median_time(lambda: run_direct(system), repeats),
                         "b": median_time(ours, repeats)}
                ship = master.instances["ship"]
                doStep = _ship_step_cost(ship)
            finally:
                master.free()
            null = Master(system, backend="null")
            own = median_time(null.run, repeats)
            for key, runner in (("c", _libcosim_runner), ("d", _ecos_runner)):
                try:
                    times[key] = median_time(runner(ssp), repeats)
                except Exception as error:          # not installed here: say so
                    times[key] = None
                    print(f"  ({key}) {'libcosim' if key == 'c' else 'ecos'} unavailable: "
                          f"{type(error).__name__}: {error}")
            rows.append((name, times, doStep, own))

    labels = {"a": "(a) Python modules in-process, no FMI", "b": "(b) our master, FMUs via fmpy",
              "c": "(c) OSP libcosim, same SSP", "d": "(d) ecos, same SSP"}
    for name, times, doStep, own in rows:
        print(f"\n{name}:")
        print(f"  {'':40} {'wall s':>8} {'us/step':>9} {'RTF':>7}")
        for key, label in labels.items():
            if times.get(key) is not None:
                t = times[key]
                print(f"  {label:40} {t:8.3f} {t / STEPS * 1e6:9.1f} {400 / t:7.0f}")
        b = times["b"]
        print(f"  b/a = {b / times['a']:.2f}" + (f"   c/b = {times['c'] / b:.2f}"
                                                 if times.get("c") else "")
              + (f"   d/b = {times['d'] / b:.2f}" if times.get("d") else ""))
        print(f"  ship FMU doStep alone: {doStep:.1f} us;  master's own cost (bookkeeping, "
              f"no FMI): {own / STEPS * 1e6:.1f} us/step;  FMI calls and slave wrappers: "
              f"{(b - times['a'] - own) / STEPS * 1e6:.1f} us/step")
    waves_b = dict((n, t) for n, t, _, _ in rows)["waves_pd"]["b"]
    print(f"\nTargets: waves_pd through the FMUs {waves_b:.3f} s (target "
          f"{TARGETS['waves_pd through the FMUs']}); b/a (target {TARGETS['b/a']}); "
          f"c/b (target {TARGETS['c/b']}) as above.")


def _ship_step_cost(ship, steps: int = 2000) -> float:
    """Microseconds per doStep of the ship FMU alone, as initialised by the master."""
    step = ship.stepper()
    started = time.perf_counter()
    for k in range(steps):
        step(400.0 + 0.1 * k, 0.1)
    return (time.perf_counter() - started) / steps * 1e6


def memory(hours: float) -> None:
    """A long calm_pd run with rows streamed to disk; peak RSS against a short run."""
    print(f"Memory: calm_pd streamed to CSV in chunks of 10,000 rows, on {machine()}")
    for duration in (3600.0, hours * 3600.0):
        code = ("import resource, time, tempfile, os\n"
                "from cosim import scenarios\nfrom cosim.core.master import Master\n"
                "m = Master(scenarios.load('calm_pd'))\n"
                "out = os.path.join(tempfile.mkdtemp(), 'run.csv')\n"
                "t = time.perf_counter()\n"
                f"rec = m.run({duration!r}, csv_path=out)\n"
                "wall = time.perf_counter() - t\n"
                "m.free()\n"
                "assert rec.error is None, rec.error\n"
                "print(rec.rows, wall, os.path.getsize(out),"
                " resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)\n"
                "os.remove(out)\n")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True).stdout.split()
        rows, wall, size, peak_kb = int(out[0]), float(out[1]), int(out[2]), int(out[3])
        print(f"  {duration / 3600:5.1f} h simulated: {rows:>8} rows, {wall:6.1f} s wall, "
              f"CSV {size / 1e6:7.1f} MB, peak RSS {peak_kb / 1024:6.1f} MB")


def sweep_throughput(runs: int, worker_counts: tuple[int, ...] = (1, 2)) -> None:
    """Runs per second of a waves_pd/waves_smc seed sweep (400 s each) on a local cluster,
    the scaling from one worker to more, and the overhead per run: in the task (its wall
    time minus the master's run) and outside it (worker time per run minus task time)."""
    from dask.distributed import Client

    from .cluster import local_cluster
    from .sweep import Spec, execute

    print(f"sweep throughput: {runs} runs of 400 s (waves_pd and waves_smc, wave seeds), "
          f"on {machine()}")
    rates = {}
    for workers in worker_counts:
        with tempfile.TemporaryDirectory() as tmp:
            spec_path = Path(tmp) / "bench.toml"
            spec_path.write_text(f'name = "bench"\n[axes]\n'
                                 f'wave_seed = {{ start = 1, count = {runs // 2} }}\n')
            spec = Spec.read(spec_path)
            started = time.perf_counter()
            cluster = local_cluster(workers)
            Client(cluster).close()
            ready = time.perf_counter()
            try:
                rows = execute(spec, Path(tmp), scheduler=cluster.scheduler_address,
                               progress=False)
            finally:
                cluster.close()
            done = time.perf_counter()
        ok = [r for r in rows if r["status"] == "ok"]
        wall = done - ready
        rates[workers] = len(ok) / wall
        simulated = sum(r["sim_seconds"] for r in ok) / len(ok)
        in_task = sum(r["seconds"] - r["sim_seconds"] for r in ok) / len(ok)
        outside = wall * workers / len(ok) - simulated - in_task
        print(f"  {workers} worker{'s' if workers > 1 else ' '}: {rates[workers]:5.2f} runs/s "
              f"({len(ok)} runs in {wall:5.1f} s; cluster start-up {ready - started:4.1f} s); "
              f"per run: simulation {simulated:5.3f} s, overhead in the task {in_task:5.3f} s "
              f"({in_task / simulated:4.1%}), outside it {outside:5.3f} s "
              f"({outside / simulated:4.1%})")
    base = min(worker_counts)
    for workers in worker_counts:
        if workers != base:
            print(f"  scaling {base} -> {workers} workers: {rates[workers] / rates[base]:4.2f}x, "
                  f"parallel efficiency {rates[workers] / rates[base] / (workers / base):4.2f} "
                  "(1.00: each worker as fast as one alone)")
