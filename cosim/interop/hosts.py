"""Run an SSP package (libcosim: or its OSP folder) in libcosim, ecos, fmpy or OMSimulator, in a
child process: libcosimpy 0.0.6 aborts its host when an FMU fails, ecos 0.7.2 ignores statuses."""
from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path
from typing import Any, Callable

import numpy as np

from fmukit.timebase import communication_point, step_count

from ..core.files import whole_file
from ..core.interrupt import STOP_SIGNALS, Interrupted, StopSignals
from ..core.system import SystemDescription, split_name
from .ssp import FMI2_ONLY, described, is_osp, unapplied_strings

ENGINES = ("libcosim", "ecos", "fmpy")
TRACED = ("ship.psi", "ship.r", "ship.delta")


class EngineError(RuntimeError):
    """An engine failed or produced undefined values; the message holds its output."""


def _libcosim(ssp: Path, system: SystemDescription, n_steps: int, signals: tuple[str, ...],
              stop: StopSignals, events: str = "") -> dict[str, np.ndarray]:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.ERROR)
    execution = (CosimExecution.from_osp_config_file if is_osp(ssp)
                 else CosimExecution.from_ssp_file)(str(ssp))
    if events:                          # OSP's scenario file, its own scenario manager's
        manager = CosimManipulator.create_scenario_manager()
        if not (execution.add_manipulator(manager) and
                execution.load_scenario(manager, events)):
            raise EngineError(f"libcosim could not load the scenario file {events}")
    slaves = {s.name.decode(): s.index for s in execution.slave_infos()}
    references = {name: {v.name.decode(): v.reference for v in execution.slave_variables(i)}
                  for name, i in slaves.items()}
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    reads = [(slaves[c], references[c][v]) for c, v in map(split_name, signals)]
    rows = []
    for k in range(n_steps):
        stop.check()
        if not execution.step():
            raise EngineError(f"libcosim failed in the step from t = "
                              f"{communication_point(system.start_time, k, system.step_size):g}"
                              " s (the FMU's message is above)")
        rows.append([observer.last_real_values(index, [vr])[0] for index, vr in reads])
    times = system.start_time + system.step_size * np.arange(1, n_steps + 1)
    return {"time": times, **dict(zip(signals, np.array(rows).T))}


def _ecos(ssp: Path, system: SystemDescription, n_steps: int, signals: tuple[str, ...],
          stop: StopSignals) -> dict[str, np.ndarray]:
    from ecospy import EcosLib, EcosSimulation
    EcosLib.set_log_level("err")
    simulation = EcosSimulation(step_size=system.step_size, ssp_path=str(ssp))
    identifiers = [f"{c}::{v}" for c, v in map(split_name, signals)]
    try:
        if not simulation.init(parameter_set="scenario"):
            raise EngineError(f"ecos failed to initialise: {EcosLib.get_last_error()}")
        rows = [[simulation.get_real(i) for i in identifiers]]
        for k in range(n_steps):
            stop.check()
            if not all(map(math.isfinite, rows[-1])):   # ecos ignores refused calls
                raise EngineError(
                    f"ecos went on, but {', '.join(signals)} read NaN from t = "
                    f"{communication_point(system.start_time, k, system.step_size):g} s: an FMU "
                    "failed (its message is above)")
            simulation.step()
            rows.append([simulation.get_real(i) for i in identifiers])
    finally:
        simulation.terminate()
        simulation.free()
    times = system.start_time + system.step_size * np.arange(n_steps + 1)
    return {"time": times, **dict(zip(signals, np.array(rows).T))}


def _fmpy(ssp: Path, system: SystemDescription, n_steps: int, signals: tuple[str, ...],
          stop: StopSignals) -> dict[str, np.ndarray]:
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import Parameter, ParameterSet
    # fmpy's runner applies no parameter bindings itself: pass the package's own values
    refuse_strings(ssp, "fmpy's SSP runner")
    parameters = ParameterSet()
    for name, component in system.components.items():
        parameters.parameters.extend(
            Parameter(name=f"{name}.{variable}", type=type(value).__name__, value=value)
            for variable, value in component.parameters.items() if not isinstance(value, str))
    result = simulate_ssp(str(ssp), start_time=system.start_time, stop_time=system.stop_time,
                          step_size=system.step_size, parameter_set=parameters)
    stop.check()                        # fmpy's runner cannot be stopped before its end
    times = np.array(result["time"]) + system.step_size   # it labels a row with the step's start
    return {"time": times, **{s: np.asarray(result[s]) for s in signals}}


RUNNERS = {"libcosim": _libcosim, "ecos": _ecos, "fmpy": _fmpy}


def refuse_strings(ssp: Path, who: str) -> None:
    """EngineError if ``ssp`` binds a String away from its FMU's default: ``who`` sets none."""
    if dropped := unapplied_strings(ssp):
        raise EngineError(f"{who} applies no String binding; it would run " + ", ".join(
            f"{v} = {default!r}, not {value!r}" for v, (value, default) in dropped.items()))


def run(engine: str, ssp: str | Path, signals: tuple[str, ...] = TRACED,
        events: str | Path | None = None) -> dict[str, np.ndarray]:
    """The traced signals of ``ssp`` run in ``engine`` (libcosim: with the timed ``events`` of
    an OSP scenario file); EngineError naming what it cannot run or with the child's output if
    it fails, ``Interrupted`` if SIGINT or SIGTERM ended it."""
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    if events is not None and engine != "libcosim":
        raise ValueError(f"{engine} runs no timed events; libcosim reads the scenario file")
    ssp = Path(ssp).resolve()
    if is_osp(ssp) and engine != "libcosim":
        raise ValueError(f"{engine} reads SSP packages, not OSP's {ssp.name}; give the .ssp")
    try:
        system, descriptions = described(ssp)
    except (OSError, KeyError, ValueError, zipfile.BadZipFile) as error:
        raise EngineError(f"{ssp} is not an SSP package this project can run ({error})") from None
    newer = [f"{name} (FMI {d.fmiVersion})" for name, d in descriptions.items()
             if d.fmiVersion != "2.0"]
    if engine in FMI2_ONLY and newer:
        raise EngineError(f"{FMI2_ONLY[engine]} runs FMI 2.0 FMUs only; {ssp.name} holds "
                          f"{', '.join(newer)}: run it with ecos or OMSimulator, or export "
                          "the FMI 2.0 package (python -m cosim.export without --fmi 3)")
    for name, component in system.components.items():
        for variable, x in component.parameters.items():
            if isinstance(x, float) and not math.isfinite(x):
                raise EngineError(f"{ssp.name}: parameter {name}.{variable} = {x} is not finite")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "trace.npz"
        events = "" if events is None else str(Path(events).resolve())
        return child_trace(engine, ssp, [sys.executable, "-c", _CHILD, engine, str(ssp), str(out),
                                         events, *signals], out, lambda path: dict(np.load(path)))


def child_trace(who: str, ssp: Path, argv: list[str], out: Path,
                read: Callable[[Path], dict[str, np.ndarray]], timeout: float = 600.0,
                **options: Any) -> dict[str, np.ndarray]:
    """``read(out)`` once ``argv`` ran ``ssp``: ``Interrupted`` if a signal stopped it, else
    EngineError with its output if it failed, ran out of time or left a signal undefined."""
    try:
        child = subprocess.run(argv, capture_output=True, text=True, timeout=timeout, **options)
    except subprocess.TimeoutExpired:
        raise EngineError(f"{who} did not finish {ssp.name} within {timeout:g} s") from None
    lines = [line for line in (child.stdout + child.stderr).strip().splitlines() if line.strip()]
    if len(lines) > 25:                 # the first 20 lines (where the cause is), the last 5
        lines[20:-5] = [f"... ({len(lines) - 25} more lines) ..."]
    log = "\n".join(lines)
    number = -child.returncode if child.returncode < 0 else child.returncode - 128
    if number in STOP_SIGNALS:          # Ctrl-C or a kill: not the engine's fault
        raise Interrupted(number)
    if child.returncode != 0 or not out.exists():
        how = (f"killed by {signal.Signals(-child.returncode).name}"
               if child.returncode < 0 else f"exit status {child.returncode}")
        raise EngineError(f"{who} failed on {ssp.name} ({how}):\n{log}")
    trace = read(out)
    for name, values in trace.items():
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise EngineError(f"{who} reported success, but {name} is undefined from "
                              f"t = {trace['time'][bad[0]]:.6g} s: an FMU refused to run "
                              f"and the engine did not stop.\n{log}")
    return trace


_CHILD = ("import sys\nfrom cosim.interop.hosts import record\n"
          "sys.exit(record(*sys.argv[1:4], tuple(sys.argv[5:]), sys.argv[4]))\n")


def record(engine: str, ssp: str, out: str, signals: tuple[str, ...], events: str = "") -> int:
    """The child's side of ``run``: 0 and the trace in ``out`` (.npz), 1 and the reason on
    stderr, or 130 / 143 if SIGINT or SIGTERM stopped it."""
    try:
        with StopSignals() as stop:
            system = described(Path(ssp))[0]
            n_steps = step_count(system.start_time, system.stop_time, system.step_size)
            result = RUNNERS[engine](Path(ssp), system, n_steps, signals, stop,
                                     *([events] if events else []))
    except Interrupted as interrupted:
        print(interrupted, file=sys.stderr)
        return interrupted.exit_status
    except Exception as error:          # the engine's own exceptions, with their message
        print(f"error: {type(error).__name__}: {error}", file=sys.stderr)
        return 1
    save_trace(Path(out), result)
    return 0


def save_trace(path: Path, result: dict[str, np.ndarray]) -> None:
    with whole_file(path) as tmp, open(tmp, "wb") as f:
        np.savez(f, **result)


_OMS_API = """import sys
from OMSimulator import SSP
ssp, result, step, temp = sys.argv[1:]
model = SSP(ssp, temp_dir=temp).instantiate()
model.setResultFile(result)
model.setFixedStepSize(float(step))
for call in (model.initialize, model.simulate, model.terminate, model.delete):
    call()
"""


def omsimulator_result(path: Path) -> dict[str, np.ndarray]:
    """'time' and each 'component.variable' of a result CSV, at each time its last row."""
    header = path.read_text().split("\n", 1)[0].replace('"', "").split(",")
    table = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    last = np.append(table[1:, 0] != table[:-1, 0], True)      # the last row of each time
    return dict(zip(["time"] + [".".join(h.split(".")[-2:]) for h in header[1:]], table[last].T))


def run_omsimulator(ssp: str | Path, home: str | Path, interface: str = "cli",
                    timeout: float = 600.0) -> dict[str, np.ndarray]:
    """The trace of ``ssp`` run in OMSimulator at ``home``, or EngineError with its output."""
    if interface not in ("cli", "api"):
        raise ValueError(f"interface must be one of cli, api, got {interface!r}")
    ssp, home = Path(ssp).resolve(), Path(home).resolve()
    refuse_strings(ssp, "OMSimulator")
    system, site = described(ssp)[0], sysconfig.get_paths()["purelib"]
    with tempfile.TemporaryDirectory() as tmp:
        result = Path(tmp) / "result.csv"
        if interface == "cli":              # its Python FMUs need libpython loaded first
            argv = [str(home / "bin" / "OMSimulator"), f"--stopTime={system.stop_time!r}",
                    f"--startTime={system.start_time!r}", f"--resultFile={result}",
                    f"--tempDir={tmp}", str(ssp)]
            env = {"LD_PRELOAD": os.path.join(sysconfig.get_config_var("LIBDIR"),
                                              sysconfig.get_config_var("LDLIBRARY")),
                   "PYTHONPATH": site}
        else:
            argv = [sys.executable, "-c", _OMS_API, str(ssp), str(result),
                    repr(system.step_size), tmp]
            env = {"PYTHONPATH": os.pathsep.join([str(home / "lib" / "x86_64-linux-gnu"), site])}
        return child_trace(f"OMSimulator ({interface})", ssp, argv, result, omsimulator_result,
                           timeout, cwd=tmp, env={**os.environ, **env})
