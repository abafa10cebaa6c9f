"""The co-simulation master: FMUs wired by a system description, stepped at a fixed step
t_k = t_0 + k h in whole nanoseconds (``fmukit.timebase``): 400 s at 0.1 s is 4001 rows."""
from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any, Callable

from fmukit.timebase import communication_point

from .events import Schedule
from .fmi import FmuInstance, read_description
from .inprocess import InProcessInstance, fallback_note, in_process_refusal
from .instance import FmuCallError, Instance
from .isolated import IsolatedInstance, one_cpu
from .isolation import Isolation
from .interrupt import StopSignals
from .recording import Recorder, Recording
from .system import SystemDescription, split_name
from .units import unit_notes
from .values import declarations, parameters
from .watchdog import Watchdog, no_limit
from .wiring import (COUPLINGS, check_connections, communication_step, feedthrough_order,
                     layout, settle)

# the FMUs through fmpy, or their Python classes (else through FMI, with a ``fallback_note``)
BACKENDS: dict[str, type[Instance]] = {"fmi": FmuInstance, "inprocess": InProcessInstance}


class Master(contextlib.AbstractContextManager):
    """Instantiate, initialise and step the components of a system description; a context
    manager: ``with Master(system) as master: recording = master.run()`` frees the FMUs."""

    def __init__(self, system: SystemDescription, coupling: str = "gauss-seidel",
                 backend: str = "fmi", overrides: dict[str, dict[str, Any]] | None = None,
                 isolation: Isolation = Isolation()):
        for what, value, known in (("coupling", coupling, COUPLINGS),
                                   ("backend", backend, BACKENDS)):
            if value not in known:
                raise ValueError(f"{what} must be one of {', '.join(known)}, got {value!r}")
        self.system, self.coupling, self.backend = system, coupling, backend
        self.isolation = isolation.check(system.components)
        self.paths = {name: system.fmu_path(name) for name in system.components}
        self.declarations = {name: declarations(read_description(path, name, system.ours(path)))
                             for name, path in self.paths.items()}
        self.configure(overrides)
        self.schedule = Schedule(system.events, self.declarations, self.paths, system.steps()[1])
        self.instances: dict[str, Instance] = {}
        self.notes = unit_notes({c: {n: d.unit for n, d in ds.items()} for c, ds in
                                 self.declarations.items()}, overrides or {}, self.overrides)
        self.backends: dict[str, str] = {}    # how each component runs
        self.calling: list[str | None] = [None]   # the component whose calls are under way
        self._recorder: Recorder | None = None
        try:
            for name, path in self.paths.items():
                note = fallback_note(name, path) if backend == "inprocess" else None
                self.notes += [note] if note else []
                kind = self.backends[name] = "fmi" if note else backend
                if isolation.isolates(name, foreign=in_process_refusal(path) is not None):
                    self.backends[name] = f"{kind}, isolated"
                    self.instances[name] = IsolatedInstance(path, name, BACKENDS[kind],
                                                            isolation.memory_limit)
                else:
                    self.instances[name] = BACKENDS[kind](path, name)
            check_connections(system, self.instances)
            self.order = feedthrough_order(system, self.instances)
            self._prepare()
        except BaseException:
            self.free()
            raise
        self.units = {c: self.instances[split_name(c)[0]].unit(split_name(c)[1])
                      for c in self.columns}

    def configure(self, overrides: dict[str, dict[str, Any]] | None = None) -> None:
        """The next run's parameters (``values.parameters``); ValueError keeps the last."""
        self.parameters, self.overrides = parameters(self.system, self.paths,
                                                     self.declarations, overrides)

    def _prepare(self) -> None:                 # anew after a reset
        self.columns, nodes = layout(self.instances, self.system.connections,
                                     self.coupling == "gauss-seidel", self.calling)
        self.nodes = [nodes[name] for name in (self.order if self.coupling == "gauss-seidel"
                                               else self.instances)]

    def reset(self) -> None:
        """Every FMU back to its state after instantiation (fmi2Reset), for another run."""
        for instance in self.instances.values():
            instance.reset()
        self._prepare()

    def initialize(self) -> None:
        """Enter initialisation, set parameters, propagate initial outputs, exit."""
        t0 = self.system.start_time
        for name, instance in self.instances.items():
            self.calling[0] = name
            instance.enter_initialization(t0)
            instance.set(self.parameters[name], time=t0)
        self.parameter_values = {name: instance.parameter_values()
                                 for name, instance in self.instances.items()}
        settle(self.nodes, len(self.columns))
        failures = []
        for name, instance in self.instances.items():
            self.calling[0] = name
            try:
                instance.exit_initialization(t0)
            except FmuCallError as error:
                failures.append(error)
        if failures:                      # the cause, not an FMU that read its NaN outputs
            raise next((f for f in failures if f.cause != "nonfinite_input"), failures[0])

    def run(self, stop_time: float | None = None,
            progress: Callable[[int, int], None] | None = None,
            csv_path: str | Path | None = None, stop: StopSignals | None = None,
            watchdog: Watchdog | None = None) -> Recording:
        """Simulate to ``stop_time``; a failure, signal or time limit ends it early, rows kept
        (``Recording.error``). ``csv_path``: the rows streamed there (else maybe TooManyRows)."""
        t0, h, n_steps = self.system.steps(stop_time)
        recorder = self._recorder = Recorder(self.columns, n_steps + 1, csv_path,
                                             run_meta(self, n_steps), self.units)
        values = [0.0] * len(self.columns)
        k, t, error, self.parameter_values = 0, t0, None, {}
        self.schedule.own.clear()
        beat = watchdog.beat if watchdog is not None else no_limit
        if watchdog is not None:
            watchdog.calling = self.calling
        try:
            beat("the initialisation")
            self.initialize()
            with one_cpu(self.instances.values()):
                for k in range(n_steps + 1):
                    t = communication_point(t0, k, h)
                    expired, signal = beat(t), stop and stop.received
                    if signal or expired:
                        t = communication_point(t0, k - 1, h) if k else t0
                        recorder.interrupted = signal.name if signal else None
                        error = (f"{'interrupted' if signal else f'{expired}: stopped'} at "
                                 f"t = {t:.6g} s, {recorder.rows} rows kept")
                        break
                    if k in self.schedule.due:
                        self.schedule.apply(k, t, self.instances, {n.name: n for n in self.nodes})
                    communication_step(self.nodes, values, t, h, k < n_steps)
                    recorder.append(t, values)
                    if progress is not None and k % 100 == 0:
                        progress(k, n_steps)
        except FmuCallError as failure:
            recorder.meta["failure"] = {"fmu": failure.instance, "call": failure.call,
                                        "time": failure.time, "status": failure.status,
                                        "cause": failure.cause}
            if stop is not None and stop.received:     # the step the signal waited for
                recorder.interrupted = stop.received.name
            error = (f"{failure}\n  (run stopped at step {k}, t = {t:.6g} s; {recorder.rows} "
                     "rows recorded)")
        finally:
            self._recorder = None
            if self.parameter_values:
                recorder.meta["parameters"] = self.parameter_values
            recording = recorder.close(error)
        return recording

    def abandon(self, reason: str) -> Recording | None:
        """The run under way's rows closed with ``reason``, for a watchdog (None if none)."""
        recorder, self._recorder = self._recorder, None
        return recorder and recorder.close(f"{reason} ({recorder.rows} rows recorded)")

    def __exit__(self, *exc_info) -> None:
        self.free()

    def free(self) -> None:
        for name, instance in self.instances.items():
            self.calling[0] = name
            instance.free()
        self.instances = {}


def run_meta(master: Master, n_steps: int) -> dict[str, Any]:
    """A run's metadata as it starts (``parameters`` and ``wall_time_s`` are added at its end)."""
    system, (t0, h, _) = master.system, master.system.steps()
    return {"system": system.name, "description": system.description,
            "scenario_file": str(system.path) if system.path else None,
            "backend": master.backend, "backends": master.backends, "notes": master.notes,
            "coupling": master.coupling, "events": [
                e.__dict__ for due in master.schedule.due.values() for e, _ in due],
            "start_time": t0, "step_size": h,
            "stop_time": communication_point(t0, n_steps, h),
            "scenario_stop_time": system.stop_time,
            "settings": master.parameters, "overrides": master.overrides,
            "fmus": {name: {"file": str(i.path), "guid": i.guid}
                     for name, i in master.instances.items()},
            "parameter_units": {name: {n: i.unit(n) for n, v in i.variables.items()
                                       if v.causality == "parameter"}
                                for name, i in master.instances.items()}}
