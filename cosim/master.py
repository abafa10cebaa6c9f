"""The co-simulation master: FMUs wired by an SSP system description, fixed step.

Time is counted in integer steps, t_k = t_0 + k h computed in whole nanoseconds
(``fmukit.timebase``, the FMUs' own time base), so no rounding accumulates and a
400 s run at 0.1 s has exactly 4000 steps and 4001 recorded rows.

Coupling orders:

- ``gauss-seidel`` (default): the FMUs are visited along the signal flow, each
  seeing its inputs at t_k. The order is derived, not configured: a component
  whose output feeds through from its inputs (declared in its model structure)
  goes before the components it feeds; outputs without feedthrough (the ship's
  states) are read at t_k before anyone is visited. On the paper's diagram this
  gives guidance -> autopilot -> ship, as in the paper's Simulink model. Each
  visit: set inputs, read the feedthrough outputs, doStep.
- ``jacobi``: every FMU reads the outputs all FMUs gave after the previous step,
  then all step (what OSP libcosim and ecos do). A direct-feedthrough signal
  (the rudder command) reaches its target one step later than in Gauss-Seidel.

Every FMU output and every connected input is recorded at every step (inputs as
the master set them, or as read back from the FMU with ``verify_inputs``). If a
call fails, the run stops with an error naming the FMU, the call and the time;
the rows recorded up to then are kept.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from operator import itemgetter
from pathlib import Path
from graphlib import CycleError, TopologicalSorter
from typing import Any, Callable

import numpy as np

from fmukit.timebase import communication_point, nanoseconds, seconds

from .fmu import FmuCallError, FmuInstance
from .inprocess import InProcessInstance
from .ssd import SystemDescription

COUPLINGS = ("gauss-seidel", "jacobi")
BACKENDS = {"fmi": FmuInstance, "inprocess": InProcessInstance}


class WiringError(ValueError):
    """The system description does not fit the FMUs it names."""


@dataclass
class Recording:
    """What a run recorded: row k holds every signal at t_k."""

    columns: list[str]
    time: np.ndarray
    data: np.ndarray
    rows: int = 0                       # complete rows held in memory
    error: str | None = None            # why the run stopped early, if it did
    meta: dict[str, Any] = field(default_factory=dict)
    path: Path | None = None            # where the rows went, if streamed to CSV

    def __getitem__(self, column: str) -> np.ndarray:
        return self.data[:self.rows, self.columns.index(column)]

    @property
    def t(self) -> np.ndarray:
        return self.time[:self.rows]

    @property
    def recorded(self) -> int:
        """Rows the run recorded: held in memory, or written to ``path`` if streamed."""
        return self.meta.get("rows_written", self.rows)

    def write_csv(self, path) -> None:
        """All complete rows, a header of column names; floats in their shortest exact form."""
        sink = _CsvSink(path, self.columns)
        sink.write(self.t, self.data[:self.rows])
        sink.close()


class _CsvSink:
    """Rows appended to a CSV file as they come, in the shortest exact float form."""

    def __init__(self, path: str | Path, columns: list[str]):
        self.path, self.rows = Path(path), 0
        self.file = open(self.path, "w")
        self.file.write(",".join(["time", *columns]) + "\n")

    def write(self, times: np.ndarray, data: np.ndarray) -> None:
        table = np.column_stack([times, data]).tolist()
        self.file.writelines(",".join(map(repr, row)) + "\n" for row in table)
        self.file.flush()
        self.rows += len(table)

    def close(self) -> None:
        self.file.close()


@dataclass
class _Node:
    """One component as the loop sees it: column blocks and prepared FMI calls."""

    name: str
    instance: Any
    state: slice = field(default_factory=lambda: slice(0, 0))        # Real outputs, no feedthrough
    feedthrough: slice = field(default_factory=lambda: slice(0, 0))  # Real, with feedthrough
    integers: slice = field(default_factory=lambda: slice(0, 0))     # Integer outputs
    inputs: slice = field(default_factory=lambda: slice(0, 0))       # connected inputs
    sources: list[int] = field(default_factory=list)   # output column of each input
    read_state: Callable | None = None
    read_feedthrough: Callable | None = None
    read_outputs: Callable | None = None               # state and feedthrough in one call
    read_integers: Callable | None = None
    write_inputs: Callable | None = None
    read_inputs: Callable | None = None
    gather: Callable | None = None                     # values -> this node's inputs
    step: Callable | None = None

    @property
    def outputs(self) -> slice:
        return slice(self.state.start, self.feedthrough.stop)


class Master:
    """Instantiate, initialise and step the components of a system description."""

    def __init__(self, system: SystemDescription, coupling: str = "gauss-seidel",
                 backend: str = "fmi",
                 overrides: dict[str, dict[str, Any]] | None = None,
                 verify_inputs: bool = False):
        if coupling not in COUPLINGS:
            raise ValueError(f"coupling must be one of {', '.join(COUPLINGS)}, got {coupling!r}")
        self.system, self.coupling, self.verify_inputs = system, coupling, verify_inputs
        self.configure(overrides)
        self.instances: dict[str, Any] = {}
        try:
            for name in system.components:
                self.instances[name] = BACKENDS[backend](system.fmu_path(name), name)
            self._check_connections()
            self.order = self._order()
            self._layout()
        except BaseException:
            self.free()
            raise

    # -- structure -------------------------------------------------------------------
    def _check_connections(self) -> None:
        for c in self.system.connections:
            for element, connector, kind in ((c.start_element, c.start_connector, "output"),
                                             (c.end_element, c.end_connector, "input")):
                instance = self.instances[element]
                if connector not in instance.variables:
                    raise WiringError(f"connection {c}: FMU '{element}' "
                                       f"({instance.path.name}) has no variable '{connector}'; "
                                       f"it has {', '.join(instance.variables)}")
                variable = instance.variables[connector]
                if variable.causality != kind or variable.type != "Real":
                    raise WiringError(f"connection {c}: {element}.{connector} is a "
                                       f"{variable.type} {variable.causality}; a connection "
                                       f"joins a Real output to a Real input")

    def _order(self) -> list[str]:
        """Gauss-Seidel order: sources of feedthrough outputs before their targets."""
        graph = {name: set() for name in self.system.components}
        for c in self.system.connections:
            if self.instances[c.start_element].feedthrough.get(c.start_connector):
                graph[c.end_element].add(c.start_element)
        try:
            sorter = TopologicalSorter(graph)
            return list(sorter.static_order())
        except CycleError as error:
            raise WiringError(f"algebraic loop through direct feedthrough: "
                               f"{' -> '.join(error.args[1])}") from None

    def _layout(self) -> None:
        """Columns in contiguous blocks per component; the prepared calls of the loop."""
        columns: list[str] = []
        nodes = {}

        def block(names: list[str]) -> slice:
            start = len(columns)
            columns.extend(names)
            return slice(start, len(columns))

        for name, instance in self.instances.items():
            outputs = [v for v in instance.variables.values() if v.causality == "output"]
            state = [v for v in outputs if v.type == "Real" and not instance.feedthrough.get(v.name)]
            ft = [v for v in outputs if v.type == "Real" and instance.feedthrough.get(v.name)]
            ints = [v for v in outputs if v.type == "Integer"]
            node = _Node(name, instance, step=instance.stepper())
            node.state = block([f"{name}.{v.name}" for v in state])
            node.feedthrough = block([f"{name}.{v.name}" for v in ft])
            node.integers = block([f"{name}.{v.name}" for v in ints])
            vrs = [v.valueReference for v in state + ft]
            node.read_state = instance.reader(vrs[:len(state)]) if state else None
            node.read_feedthrough = instance.reader(vrs[len(state):]) if ft else None
            node.read_outputs = instance.reader(vrs) if vrs else None
            node.read_integers = (instance.integer_reader([v.valueReference for v in ints])
                                  if ints else None)
            nodes[name] = node
        for name, node in nodes.items():
            incoming = [c for c in self.system.connections if c.end_element == name]
            node.inputs = block([f"{name}.{c.end_connector}" for c in incoming])
            if incoming:
                vrs = [self.instances[name].vr(c.end_connector) for c in incoming]
                node.sources = [columns.index(f"{c.start_element}.{c.start_connector}")
                                for c in incoming]
                node.write_inputs = self.instances[name].writer(vrs)
                node.read_inputs = self.instances[name].reader(vrs)
                node.gather = itemgetter(*node.sources) if len(node.sources) > 1 else \
                    (lambda values, i=node.sources[0]: (values[i],))
        self.columns = columns
        self.nodes = [nodes[name] for name in (self.order if self.coupling == "gauss-seidel"
                                               else self.instances)]

    # -- running -------------------------------------------------------------------
    def configure(self, overrides: dict[str, dict[str, Any]] | None = None) -> None:
        """Parameters for the next run: the system's, updated by ``overrides``."""
        parameters = {name: dict(c.parameters) for name, c in self.system.components.items()}
        for component, values in (overrides or {}).items():
            if component not in parameters:
                raise ValueError(f"--set names the component '{component}'; the system has "
                                 f"{', '.join(parameters)}")
            parameters[component].update(values)
        self.parameters = parameters

    def reset(self) -> None:
        """Return every FMU to its state after instantiation (fmi2Reset), for another run."""
        for instance in self.instances.values():
            instance.reset()

    def initialize(self) -> None:
        """Enter initialisation, set parameters, propagate initial outputs, exit."""
        t0 = self.system.start_time
        for name, instance in self.instances.items():
            instance.enter_initialization(t0)
            instance.set(self.parameters[name], time=t0)
        values = [0.0] * len(self.columns)
        for _ in self.instances:          # enough passes for any acyclic chain
            for node in self.nodes:
                if node.read_outputs:
                    values[node.outputs] = node.read_outputs()
                self._apply_inputs(node, values)
        for instance in self.instances.values():
            instance.exit_initialization(t0)

    def _apply_inputs(self, node: _Node, values: list[float]) -> None:
        if node.write_inputs:
            inputs = node.gather(values)
            node.write_inputs(inputs)
            values[node.inputs] = node.read_inputs() if self.verify_inputs else inputs

    def run(self, stop_time: float | None = None,
            progress: Callable[[int, int], None] | None = None,
            csv_path: str | Path | None = None, chunk_rows: int = 10_000) -> Recording:
        """Simulate to stop_time (default: the system's); never raises on an FMU error.

        With ``csv_path`` the rows go to that CSV file in chunks of ``chunk_rows`` as
        the run proceeds, and memory stays flat however long the run; the returned
        recording then holds no rows (``rows`` counts those written).
        """
        system = self.system
        t0, h = system.start_time, seconds(nanoseconds(system.step_size))
        stop = system.stop_time if stop_time is None else stop_time
        n_steps, remainder = divmod(nanoseconds(stop) - nanoseconds(t0), nanoseconds(h))
        if remainder or n_steps < 1:
            raise ValueError(f"stop time {stop} s is not a whole number of {h} s steps "
                             f"after {t0} s")
        chunk = n_steps + 1 if csv_path is None else min(chunk_rows, n_steps + 1)
        recording = Recording(self.columns, np.empty(chunk), np.full((chunk, len(self.columns)),
                                                                    np.nan),
                              meta={"system": system.name, "coupling": self.coupling,
                                    "step_size": h})
        sink = _CsvSink(csv_path, self.columns) if csv_path is not None else None
        times, data = recording.time, recording.data
        values = [0.0] * len(self.columns)
        nodes = self.nodes
        gauss_seidel = self.coupling == "gauss-seidel"
        k, t, row = 0, t0, 0
        try:
            self.initialize()
            for k in range(n_steps + 1):
                t = communication_point(t0, k, h)
                last = k == n_steps
                if gauss_seidel:
                    for node in nodes:
                        if node.read_state:
                            values[node.state] = node.read_state()
                    for node in nodes:
                        if node.write_inputs:
                            self._apply_inputs(node, values)
                        if node.read_feedthrough:
                            values[node.feedthrough] = node.read_feedthrough()
                        if node.read_integers:
                            values[node.integers] = node.read_integers()
                        if not last:
                            node.step(t, h)
                    times[row], data[row] = t, values
                else:
                    for node in nodes:
                        if node.read_outputs:
                            values[node.outputs] = node.read_outputs()
                        if node.read_integers:
                            values[node.integers] = node.read_integers()
                    for node in nodes:
                        if node.write_inputs:
                            self._apply_inputs(node, values)
                    times[row], data[row] = t, values
                    if not last:
                        for node in nodes:
                            node.step(t, h)
                row += 1
                recording.rows = row
                if sink is not None and (row == chunk or last):
                    sink.write(times[:row], data[:row])
                    row = 0
                if progress is not None and k % 100 == 0:
                    progress(k, n_steps)
        except FmuCallError as error:
            recording.error = f"{error}\n  (run stopped at step {k}, t = {t:.6g} s; " \
                              f"{(sink.rows if sink else 0) + row} rows recorded)"
            if sink is not None:
                sink.write(times[:row], data[:row])
        finally:
            if sink is not None:
                sink.close()
                recording.rows, recording.path = 0, sink.path
                recording.meta["rows_written"] = sink.rows
        return recording

    def free(self) -> None:
        for instance in self.instances.values():
            instance.free()
        self.instances = {}
