"""The co-simulation master: FMUs wired by an SSP system description, stepped at a fixed step.

Time is counted in integer steps, t_k = t_0 + k h computed in whole nanoseconds
(``fmukit.timebase``, the FMUs' own time base), so no rounding accumulates and a
400 s run at 0.1 s has exactly 4000 steps and 4001 recorded rows.

The master wires and delegates: ``wiring`` checks the connections, derives the
Gauss-Seidel order from the declared feedthrough and lays out the columns;
``coupling`` exchanges the signals and steps the FMUs at each communication
point (Gauss-Seidel or Jacobi); ``recording`` keeps the rows, in memory or
streamed to CSV. Every FMU output and every connected input is recorded at every
step (inputs as the master set them, or as read back from the FMU with
``verify_inputs``). If a call fails, the run stops with an error naming the FMU,
the call and the time; the rows recorded up to then are kept. So does a run asked
to stop (``cosim.core.interrupt``: Ctrl-C, SIGTERM), between two steps.
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable

from fmukit.timebase import communication_point, nanoseconds, seconds, step_count

from .coupling import COUPLINGS
from .fmi import FmuInstance, read_description
from .inprocess import InProcessInstance, fallback_note
from .instance import FmuCallError, Instance
from .interrupt import StopSignals
from .null import NullInstance
from .recording import Recorder, Recording
from .ssd import SystemDescription, split_name
from .values import declarations, parameters
from .watchdog import TimeLimit, Watchdog, no_limit
from .wiring import check_connections, feedthrough_order, layout


BACKENDS: dict[str, type[Instance]] = {"fmi": FmuInstance, "inprocess": InProcessInstance,
                                       "null": NullInstance}
"""fmi: the FMUs through fmpy; inprocess: their Python classes without FMI (an FMU that
is not current in this process runs through FMI, with a note:
``cosim.core.inprocess.fallback_note``, the one place that decides it); null: nothing
but the FMUs' interfaces, to measure the master's own cost (``cosim.core.null``)."""
RUN_BACKENDS = ("fmi", "inprocess")
"""The backends a run of a scenario may take (null measures the master only)."""


class Master:
    """Instantiate, initialise and step the components of a system description.

    A context manager: ``with Master(system) as master: recording = master.run()``
    frees the FMUs however the block ends.
    """

    def __init__(self, system: SystemDescription, coupling: str = "gauss-seidel",
                 backend: str = "fmi", overrides: dict[str, dict[str, Any]] | None = None,
                 verify_inputs: bool = False):
        for what, value, known in (("coupling", coupling, COUPLINGS),
                                   ("backend", backend, BACKENDS)):
            if value not in known:
                raise ValueError(f"{what} must be one of {', '.join(known)}, got {value!r}")
        self.system, self.coupling, self.backend = system, coupling, backend
        self.paths = {name: system.fmu_path(name) for name in system.components}
        self.declarations = {name: declarations(read_description(path, name))
                             for name, path in self.paths.items()}
        self.configure(overrides)
        self.instances: dict[str, Instance] = {}
        self.notes: list[str] = []        # what the user should know about how this runs
        self.backends: dict[str, str] = {}    # how each component runs
        try:
            for name, path in self.paths.items():
                self.instances[name] = self._instantiate(path, name)
            check_connections(system, self.instances)
            self.order = feedthrough_order(system, self.instances)
            self.verify_inputs = verify_inputs
            self._prepare()
        except BaseException:
            self.free()
            raise
        self.units = {column: self.instances[component].unit(variable)
                      for column in self.columns
                      for component, variable in [split_name(column)]}

    def _instantiate(self, path: Path, name: str) -> Instance:
        backend = self.backend
        note = fallback_note(name, path) if backend == "inprocess" else None
        if note:
            backend = "fmi"
            self.notes.append(note)
        self.backends[name] = backend
        return BACKENDS[backend](path, name)

    def configure(self, overrides: dict[str, dict[str, Any]] | None = None) -> None:
        """Parameters for the next run: the system's, updated by ``overrides``, each checked
        against its FMU's model description before any FMU call and kept as it will be set
        (``cosim.core.values.parameters``); ValueError naming a value refused, the
        parameters left as they were."""
        self.parameters, self.overrides = parameters(self.system, self.paths,
                                                     self.declarations, overrides)

    def _prepare(self) -> None:
        """Lay out the columns and prepare each component's calls for the loop."""
        self.columns, nodes = layout(self.instances, self.system.connections,
                                     self.verify_inputs)
        self.nodes = [nodes[name] for name in (self.order if self.coupling == "gauss-seidel"
                                               else self.instances)]

    def reset(self) -> None:
        """Return every FMU to its state after instantiation (fmi2Reset), for another run."""
        for instance in self.instances.values():
            instance.reset()
        self._prepare()                   # a backend's prepared calls may not survive a reset

    def initialize(self) -> None:
        """Enter initialisation, set parameters, propagate initial outputs, exit.

        ``parameter_values`` then holds every parameter as the FMUs hold it (defaults and
        what was set), read before the FMUs judge them.
        """
        t0 = self.system.start_time
        for name, instance in self.instances.items():
            instance.enter_initialization(t0)
            instance.set(self.parameters[name], time=t0)
        self.parameter_values = {name: instance.parameter_values()
                                 for name, instance in self.instances.items()}
        values = [0.0] * len(self.columns)
        for _ in self.instances:          # enough passes for any acyclic chain
            for node in self.nodes:
                if node.read_outputs:
                    values[node.outputs] = node.read_outputs()
                if node.apply_inputs:
                    node.apply_inputs(values)
        failures = []
        for instance in self.instances.values():
            try:
                instance.exit_initialization(t0)
            except FmuCallError as error:
                failures.append(error)
        if failures:                      # the cause, not an FMU that read its NaN outputs
            raise next((f for f in failures if f.cause != "nonfinite_input"), failures[0])

    def run(self, stop_time: float | None = None,
            progress: Callable[[int, int], None] | None = None,
            csv_path: str | Path | None = None, chunk_rows: int = 10_000,
            stop: StopSignals | None = None, watchdog: Watchdog | None = None) -> Recording:
        """Simulate to stop_time (default: the system's); never raises on an FMU error.

        ValueError if the stop time is not a whole number of steps after the start, or
        if the rows would not fit in memory. With ``csv_path`` the rows go to that CSV
        file in chunks of ``chunk_rows`` as the run proceeds, and memory stays flat
        however long the run; the returned recording then holds no rows itself
        (``rows`` counts those written). Once ``stop`` has received a signal, the run
        ends before the next step (``Recording.interrupted``). A ``watchdog`` times
        the initialisation and each step; a limit passed ends the run with an error
        (``cosim.core.watchdog``), as an FMU failure does.
        """
        t0, h, n_steps = self.steps(stop_time)
        meta = self.run_meta(n_steps)
        recorder = Recorder(self.columns, n_steps + 1, csv_path, chunk_rows, meta=meta,
                            units=self.units)
        exchange, nodes, values = COUPLINGS[self.coupling], self.nodes, [0.0] * len(self.columns)
        k, t, error, started = 0, t0, None, time.perf_counter()
        self.parameter_values = {}
        self._recorder = recorder
        beat = watchdog.beat if watchdog is not None else no_limit
        try:
            beat("the initialisation")
            self.initialize()
            for k in range(n_steps + 1):
                t = communication_point(t0, k, h)
                expired = beat(t)
                if (stop is not None and stop.received) or expired:
                    t = communication_point(t0, k - 1, h) if k else t0
                    if stop is not None and stop.received:
                        recorder.interrupted = stop.received.name
                        error = f"interrupted at t = {t:.6g} s, {recorder.rows} rows kept"
                    else:
                        error = f"{expired}: stopped at t = {t:.6g} s, {recorder.rows} rows kept"
                    break
                exchange(nodes, values, t, h, k < n_steps)
                recorder.append(t, values)
                if progress is not None and k % 100 == 0:
                    progress(k, n_steps)
        except (FmuCallError, TimeLimit) as failure:
            error = f"{failure}\n  " if isinstance(failure, FmuCallError) else ""
            if watchdog is not None and watchdog.expired:
                error = f"{watchdog.expired}\n  {error}"
            if stop is not None and stop.received:     # the step the signal waited for
                recorder.interrupted = stop.received.name
            error += f"(run stopped at step {k}, t = {t:.6g} s; {recorder.rows} rows recorded)"
        finally:
            self._recorder = None
            if self.parameter_values:
                meta["parameters"] = self.parameter_values
            meta["wall_time_s"] = time.perf_counter() - started
            recording = recorder.close(error)
        return recording

    def steps(self, stop_time: float | None = None) -> tuple[float, float, int]:
        """(t0, h, number of steps) of a run to ``stop_time`` (default: the system's), h on
        the FMUs' time base; ValueError unless the stop time is a whole number of steps."""
        system = self.system
        t0, h = system.start_time, seconds(nanoseconds(system.step_size))
        return t0, h, step_count(t0, system.stop_time if stop_time is None else stop_time, h)

    def run_meta(self, n_steps: int) -> dict[str, Any]:
        """What a run of ``n_steps`` records about itself before it starts: the system, the
        backends, the time grid, the settings and the FMUs (``parameters`` and
        ``wall_time_s`` are added as it ends)."""
        system, t0, h = self.system, self.system.start_time, self.steps()[1]
        return {"system": system.name, "description": system.description,
                "scenario_file": str(system.path) if system.path else None,
                "backend": self.backend, "backends": self.backends, "notes": self.notes,
                "coupling": self.coupling, "start_time": t0,
                "step_size": h, "stop_time": communication_point(t0, n_steps, h),
                "scenario_stop_time": system.stop_time,
                "settings": self.parameters, "overrides": self.overrides,
                "fmus": {name: {"file": str(i.path), "guid": getattr(i, "guid", None)}
                         for name, i in self.instances.items()},
                "parameter_units": {
                    name: {n: i.unit(n) for n, v in i.variables.items()
                           if v.causality == "parameter"}
                    for name, i in self.instances.items()}}

    def abandon(self, reason: str) -> Recording | None:
        """The rows of the run under way, closed with ``reason`` as its error, for a
        watchdog whose run will never return (None if no run is under way)."""
        recorder, self._recorder = getattr(self, "_recorder", None), None
        if recorder is None:
            return None
        return recorder.close(f"{reason} ({recorder.rows} rows recorded)")

    def __enter__(self) -> Master:
        return self

    def __exit__(self, *exc_info) -> None:
        self.free()

    def free(self) -> None:
        """Terminate and free every FMU (what leaving ``with Master(...) as master:`` does,
        on every path)."""
        for instance in self.instances.values():
            instance.free()
        self.instances = {}
