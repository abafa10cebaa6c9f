"""The engine benchmarks of ``python -m cosim.bench`` (figures printed, never asserted):
``engines``, ``overhead`` and ``memory``; the helpers the sweep benchmarks share."""
from __future__ import annotations

import os
import platform
import resource
import statistics
import tempfile
import time
from pathlib import Path
from typing import Callable

from .. import scenarios
from ..core.isolation import Isolation
from ..core.master import BACKENDS, Master
from ..ensemble.reference import run_direct
from . import in_child

STEPS = 4000
ROWS = {"direct": "(a) the modules wired by hand (run_direct)",
        "inprocess": "(b) our master, in-process backend",
        "fmi": "(c) our master, FMUs via fmpy",
        "libcosim": "(d) OSP libcosim, same SSP",
        "ecos": "(e) ecos, same SSP",
        "floor": "(f) FMI floor: a + calls x cost",
        "isolated": "(g) our master, every FMU isolated, via fmpy",
        "isolated_inprocess": "(h) ... every FMU isolated, in-process"}
RATIOS = (("b/a", "inprocess", "direct"), ("c/b", "fmi", "inprocess"), ("c/f", "fmi", "floor"),
          ("d/c", "libcosim", "fmi"), ("e/c", "ecos", "fmi"), ("g/c", "isolated", "fmi"),
          ("h/c", "isolated_inprocess", "fmi"))


def peak_rss_mb() -> float:
    """This process's peak RSS, MB: Linux's VmHWM (``ru_maxrss`` keeps a forked parent's)."""
    try:
        return next(int(line.split()[1]) / 1024 for line in
                    Path("/proc/self/status").read_text().splitlines() if line.startswith("VmHWM:"))
    except (OSError, StopIteration):
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def machine() -> str:
    """One line on the machine and its load now: its CPU (family, model and AVX-512, which
    numpy's kernels use), cores, Python, OS."""
    try:
        info = dict(line.split(":", 1) for line in Path("/proc/cpuinfo").read_text().split(
            "\n\n")[0].splitlines() if ":" in line)
        info = {key.strip(): value.strip() for key, value in info.items()}
        avx512 = "AVX-512" if "avx512f" in info["flags"].split() else "no AVX-512"
        cpu = (f"{info['model name']} (family {info['cpu family']}, model {info['model']}, "
               f"{avx512})")
    except (OSError, KeyError):
        cpu = platform.processor() or platform.machine()
    return (f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"{platform.system()} {platform.release()}; {load()}")


def load() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} (1, 5, 15 min)"


def side_by_side(runners: dict[str, Callable[[], object]], repeats: int) -> dict[str, float]:
    """Median wall time of each runner, timed in turn round after round after a warm-up."""
    times: dict[str, list[float]] = {key: [] for key in runners}
    for round_ in range(repeats + 1):
        for key, run in runners.items():
            started = time.perf_counter()
            run()
            if round_:
                times[key].append(time.perf_counter() - started)
    return {key: statistics.median(values) for key, values in times.items()}


def _libcosim_runner(ssp: Path) -> Callable[[], None]:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)

    def run() -> None:
        if not CosimExecution.from_ssp_file(str(ssp)).simulate_until(400 * 10**9):   # ns
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


def engines(repeats: int) -> dict[str, dict[str, float]]:
    """calm_pd and waves_pd by each of ``ROWS``, printed with their ratios; the times."""
    from ..interop.ssp import export

    print(f"Engines on the same system, 400 s = {STEPS} macro steps of 0.1 s, median of "
          f"{repeats} runs taken in turn, on {machine()}")
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in ("calm_pd", "waves_pd"):
            system = scenarios.load(name)
            ssp = export(name, Path(tmp))
            with Master(system, backend="inprocess") as inprocess, \
                    Master(system, backend="fmi") as fmi, \
                    Master(system, isolation=Isolation("all")) as isolated, \
                    Master(system, "gauss-seidel", "inprocess",
                           isolation=Isolation("all")) as isolated_inprocess:
                require("in-process backend", inprocess.notes)
                runners = {"direct": lambda: run_direct(inprocess),
                           "inprocess": _master_runner(inprocess), "fmi": _master_runner(fmi),
                           "isolated": _master_runner(isolated),
                           "isolated_inprocess": _master_runner(isolated_inprocess)}
                for key, make in (("libcosim", _libcosim_runner), ("ecos", _ecos_runner)):
                    try:
                        runners[key] = make(ssp)
                    except Exception as error:          # not installed here: say so
                        print(f"  {key} unavailable: {type(error).__name__}: {error}")
                times = results[name] = side_by_side(runners, repeats)
                calls = sum(1 + sum(bool(call) for call in (   # a step's calls, doStep too
                    node.read_state, node.apply_inputs, node.read_feedthrough,
                    node.read_integers)) for node in fmi.nodes)
                per_call = fmi_call_cost(fmi)
            times["floor"] = times["direct"] + STEPS * calls * per_call
            print(f"\n{name}:\n  {'':44} {'wall s':>7} {'us/step':>8} {'RTF':>6} {'x (a)':>6}")
            for key, label in ROWS.items():
                if key in times:
                    t = times[key]
                    print(f"  {label:44} {t:7.3f} {t / STEPS * 1e6:8.1f} {400 / t:6.0f} "
                          f"{t / times['direct']:6.2f}")
            ratios = [f"{r} = {times[a] / times[b]:.2f}" for r, a, b in RATIOS if a in times]
            print(f"  {'   '.join(ratios)}\n  (f): {calls} FMI calls per step x "
                  f"{per_call * 1e6:.1f} us per call (measured on the PD FMU in the running "
                  "loop) + the model compute (a)")
    calm, waves = results["calm_pd"], results["waves_pd"]
    print(f"\nwaves_pd / calm_pd in-process: {waves['inprocess'] / calm['inprocess']:.2f} "
          f"(wired by hand: {waves['direct'] / calm['direct']:.2f})")
    return results


def require(route: str, notes: list[str]) -> None:
    """RuntimeError if ``route`` cannot be measured: ``notes`` say what would run otherwise."""
    if notes:
        raise RuntimeError(f"the {route} cannot be measured: " + "; ".join(notes))


def _master_runner(master) -> Callable[[], None]:
    def run() -> None:
        master.reset()
        if master.run().error:
            raise RuntimeError(f"our master failed ({master.backend})")
    return run


def fmi_call_cost(master) -> float:
    """Seconds per FMI call of the cheapest kind: setReal, getReal of one autopilot value."""
    calls = 20_000
    master.reset()
    master.initialize()
    instance = master.instances["autopilot"]
    write = instance.writer([instance.vr("psi_d")])
    read = instance.reader([instance.vr("delta_c")])
    started = time.perf_counter()
    for _ in range(calls // 2):
        write([0.1])
        read()
    return (time.perf_counter() - started) / calls


def _nothing(*args, **kwargs) -> None:
    return None


def _idle_reader(self, vrs: list[int], kind: str = "Real") -> Callable[[], list[float]]:
    values = [0.0] * len(vrs)
    return lambda: values


# the in-process instance's prepared calls doing nothing: the master's own work remains
IDLE_CALLS = {"reader": _idle_reader,
              "writer": lambda self, vrs: _nothing, "stepper": lambda self: _nothing}


def overhead(repeats: int) -> dict[str, float]:
    """us per step of calm_pd, the ship's step idle: by hand, by the master idle, in-process."""
    from unittest import mock

    from ship_fmu.vessel import Vessel

    from ..core.inprocess import InProcessInstance

    system = scenarios.load("calm_pd")
    with Master(system, backend="inprocess") as inprocess, \
            Master(system, backend="inprocess") as idle:
        require("in-process backend", inprocess.notes)

        def idle_run() -> None:
            with mock.patch.multiple(InProcessInstance, **IDLE_CALLS):
                _master_runner(idle)()
        with mock.patch.object(Vessel, "step", _nothing):
            times = side_by_side({"direct": lambda: run_direct(inprocess), "idle": idle_run,
                                  "inprocess": _master_runner(inprocess)}, repeats)
    per_step = {key: t / STEPS * 1e6 for key, t in times.items()}
    print(f"What the routes do besides the models: calm_pd, {STEPS} steps with the ship's step "
          f"doing nothing, median of {repeats} runs taken in turn, on {machine()}")
    for key, label in (("direct", "the modules wired by hand (run_direct)"),
                       ("idle", "our master, its calls into the FMUs idle"),
                       ("inprocess", "our master, in-process backend")):
        print(f"  {label:48} {per_step[key]:6.1f} us/step")
    print(f"  the in-process master beyond the modules wired by hand: "
          f"{per_step['inprocess'] - per_step['direct']:.1f} us/step (its calls into the slaves, "
          "and its bookkeeping beyond direct's)")
    return per_step


def memory(hours: float) -> None:
    """Peak RSS of a long calm_pd run streamed to disk against a short one's, each backend."""
    print(f"Memory: calm_pd streamed to CSV in chunks of 10,000 rows, on {machine()}")
    for backend in BACKENDS:
        for duration in (3600.0, hours * 3600.0):
            rows, wall, size, peak = in_fresh_process(f"calm_pd on {backend}", streamed_run,
                                                      backend, duration)
            print(f"  {backend:9} {duration / 3600:5.1f} h simulated: {rows:>8.0f} rows, "
                  f"{wall:6.1f} s wall, CSV {size / 1e6:7.1f} MB, peak RSS {peak:6.1f} MB")


def streamed_run(backend: str, duration: float) -> tuple[int, float, int, float]:
    """(rows, wall s, CSV bytes, peak RSS MB) of calm_pd to ``duration`` streamed to disk."""
    with tempfile.TemporaryDirectory() as tmp, \
            Master(scenarios.load("calm_pd"), backend=backend) as master:
        started = time.perf_counter()
        recording = master.run(duration, csv_path=Path(tmp) / "run.csv")
        wall = time.perf_counter() - started
        if recording.error:
            raise RuntimeError(recording.error)
        return recording.rows, wall, recording.path.stat().st_size, peak_rss_mb()


def in_fresh_process(what: str, function: Callable, *args: object) -> list[float]:
    """``function(*args)`` in a fresh process (its own peak memory): the numbers it returns."""
    name = function.__name__
    code = f"from {function.__module__} import {name}; print(*{name}(*{args!r}))"
    return [float(value) for value in in_child(what, code).split()]
