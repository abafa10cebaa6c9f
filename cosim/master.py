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
    rows: int = 0                       # complete rows
    error: str | None = None            # why the run stopped early, if it did
    meta: dict[str, Any] = field(default_factory=dict)

    def __getitem__(self, column: str) -> np.ndarray:
        return self.data[:self.rows, self.columns.index(column)]

    @property
    def t(self) -> np.ndarray:
        return self.time[:self.rows]

    def write_csv(self, path) -> None:
        """All complete rows, a header of column names; floats in their shortest exact form."""
        table = np.column_stack([self.t, self.data[:self.rows]]).tolist()
        with open(path, "w") as f:
            f.write(",".join(["time", *self.columns]) + "\n")
            f.writelines(",".join(map(repr, row)) + "\n" for row in table)


@dataclass
class _Node:
    """One component as the loop sees it."""

    name: str
    instance: Any
    state_out: list[int]                # value references: outputs without feedthrough
    state_cols: list[int]               # their columns
    ft_out: list[int]                   # outputs with feedthrough
    ft_cols: list[int]
    int_out: list[int]                  # Integer outputs (evaluated with the feedthrough)
    int_cols: list[int]
    in_vrs: list[int]                   # connected inputs
    in_cols: list[int]
    in_sources: list[int]               # column of the output each input is connected to


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
        columns: list[str] = []
        nodes = {}
        for name, instance in self.instances.items():
            outputs = [v for v in instance.variables.values() if v.causality == "output"]
            reals = [v for v in outputs if v.type == "Real"]
            ints = [v for v in outputs if v.type == "Integer"]
            state = [v for v in reals if not instance.feedthrough.get(v.name)]
            ft = [v for v in reals if instance.feedthrough.get(v.name)]
            node = _Node(name, instance, [], [], [], [], [], [], [], [], [])
            for group, vrs, cols in ((state, node.state_out, node.state_cols),
                                     (ft, node.ft_out, node.ft_cols),
                                     (ints, node.int_out, node.int_cols)):
                for v in group:
                    vrs.append(v.valueReference)
                    cols.append(len(columns))
                    columns.append(f"{name}.{v.name}")
            nodes[name] = node
        for c in self.system.connections:
            node = nodes[c.end_element]
            node.in_vrs.append(self.instances[c.end_element].vr(c.end_connector))
            node.in_cols.append(len(columns))
            node.in_sources.append(columns.index(f"{c.start_element}.{c.start_connector}"))
            columns.append(f"{c.end_element}.{c.end_connector}")
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
                self._read(node, values, node.state_out + node.ft_out,
                           node.state_cols + node.ft_cols)
                self._apply_inputs(node, values)
        for instance in self.instances.values():
            instance.exit_initialization(t0)

    def _read(self, node: _Node, values: list[float], vrs: list[int], cols: list[int]) -> None:
        if vrs:
            for col, value in zip(cols, node.instance.get_real(vrs)):
                values[col] = value

    def _apply_inputs(self, node: _Node, values: list[float]) -> None:
        if node.in_vrs:
            inputs = [values[src] for src in node.in_sources]
            node.instance.set_real(node.in_vrs, inputs)
            if self.verify_inputs:
                inputs = node.instance.get_real(node.in_vrs)
            for col, value in zip(node.in_cols, inputs):
                values[col] = value

    def run(self, stop_time: float | None = None,
            progress: Callable[[int, int], None] | None = None) -> Recording:
        """Simulate to stop_time (default: the system's); never raises on an FMU error."""
        system = self.system
        t0, h = system.start_time, seconds(nanoseconds(system.step_size))
        stop = system.stop_time if stop_time is None else stop_time
        n_steps, remainder = divmod(nanoseconds(stop) - nanoseconds(t0), nanoseconds(h))
        if remainder or n_steps < 1:
            raise ValueError(f"stop time {stop} s is not a whole number of {h} s steps "
                             f"after {t0} s")
        times = np.array([communication_point(t0, k, h) for k in range(n_steps + 1)])
        recording = Recording(self.columns, times,
                              np.full((n_steps + 1, len(self.columns)), np.nan),
                              meta={"system": system.name, "coupling": self.coupling,
                                    "step_size": h})
        values = [0.0] * len(self.columns)
        gauss_seidel = self.coupling == "gauss-seidel"
        k, t = 0, t0
        try:
            self.initialize()
            for k in range(n_steps + 1):
                t = float(times[k])
                if gauss_seidel:
                    for node in self.nodes:
                        self._read(node, values, node.state_out, node.state_cols)
                    for node in self.nodes:
                        self._apply_inputs(node, values)
                        self._read(node, values, node.ft_out, node.ft_cols)
                        self._read_int(node, values)
                        if k < n_steps:
                            node.instance.do_step(t, h)
                    recording.data[k] = values
                else:
                    for node in self.nodes:
                        self._read(node, values, node.state_out + node.ft_out,
                                   node.state_cols + node.ft_cols)
                        self._read_int(node, values)
                    for node in self.nodes:
                        self._apply_inputs(node, values)
                    recording.data[k] = values
                    if k < n_steps:
                        for node in self.nodes:
                            node.instance.do_step(t, h)
                recording.rows = k + 1
                if progress is not None and k % 100 == 0:
                    progress(k, n_steps)
        except FmuCallError as error:
            recording.error = f"{error}\n  (run stopped at step {k}, t = {t:.6g} s; " \
                              f"{recording.rows} rows recorded)"
        return recording

    def _read_int(self, node: _Node, values: list[float]) -> None:
        if node.int_out:
            for col, value in zip(node.int_cols, node.instance.get_integer(node.int_out)):
                values[col] = value

    def free(self) -> None:
        for instance in self.instances.values():
            instance.free()
        self.instances = {}
