"""How the components of a system connect: checks, the Gauss-Seidel order, the loop's layout.

``check_connections`` refuses a connection that does not join a Real output to a Real input;
``feedthrough_order`` puts a component whose outputs feed through from its inputs (its model
structure) before those it feeds; ``layout`` gives every signal a column, in blocks per
component, and prepares each component's calls (a ``Node``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from graphlib import CycleError, TopologicalSorter
from operator import itemgetter
from typing import Callable

from .instance import Instance
from .system import Connection, SystemDescription


class WiringError(ValueError):
    """The system description does not fit the FMUs it names."""


def check_connections(system: SystemDescription, instances: dict[str, Instance]) -> None:
    """WiringError naming the connection that does not join a Real output to a Real input."""
    for c in system.connections:
        for element, connector, kind in ((c.start_element, c.start_connector, "output"),
                                         (c.end_element, c.end_connector, "input")):
            instance = instances[element]
            if connector not in instance.variables:
                raise WiringError(f"connection {c}: FMU '{element}' "
                                  f"({instance.path.name}) has no variable '{connector}'; "
                                  f"it has {', '.join(instance.variables)}")
            variable = instance.variables[connector]
            if variable.causality != kind or variable.type != "Real":
                raise WiringError(f"connection {c}: {element}.{connector} is a "
                                  f"{variable.type} {variable.causality}; a connection "
                                  f"joins a Real output to a Real input")


def feedthrough_order(system: SystemDescription, instances: dict[str, Instance]) -> list[str]:
    """Gauss-Seidel order: sources of feedthrough outputs before their targets."""
    graph = {name: set() for name in system.components}
    for c in system.connections:
        if instances[c.start_element].feedthrough.get(c.start_connector):
            graph[c.end_element].add(c.start_element)
    try:
        return list(TopologicalSorter(graph).static_order())
    except CycleError as error:
        raise WiringError(f"algebraic loop through direct feedthrough: "
                          f"{' -> '.join(error.args[1])}") from None


@dataclass
class Node:
    """One component as the loop sees it: its column blocks and prepared calls (None where
    it has nothing of that kind)."""

    name: str
    instance: Instance
    step: Callable[[float, float], None]
    state: slice                        # Real outputs, no feedthrough
    feedthrough: slice                  # Real outputs, with feedthrough
    integers: slice                     # Integer outputs
    inputs: slice = field(default_factory=lambda: slice(0, 0))     # connected inputs
    read_state: Callable[[], list[float]] | None = None
    read_feedthrough: Callable[[], list[float]] | None = None
    read_outputs: Callable[[], list[float]] | None = None   # state and feedthrough at once
    read_integers: Callable[[], list[int]] | None = None
    apply_inputs: Callable[[list[float]], None] | None = None  # values -> this node's inputs

    @property
    def outputs(self) -> slice:
        return slice(self.state.start, self.feedthrough.stop)


def layout(instances: dict[str, Instance], connections: list[Connection],
           verify_inputs: bool = False) -> tuple[list[str], dict[str, Node]]:
    """(columns, nodes by name): every output, then every connected input, per component.
    A node's ``apply_inputs(values)`` sets its inputs from their sources and records them
    in ``values``: as sent, or as read back with ``verify_inputs``."""
    columns: list[str] = []

    def block(name: str, variables: list) -> slice:
        columns.extend(f"{name}.{v}" for v in variables)
        return slice(len(columns) - len(variables), len(columns))

    nodes = {}
    for name, instance in instances.items():
        outputs = [v for v in instance.variables.values() if v.causality == "output"]
        reals = [v for v in outputs if v.type == "Real"]
        state = [v.name for v in reals if not instance.feedthrough.get(v.name)]
        ft = [v.name for v in reals if instance.feedthrough.get(v.name)]
        ints = [v.name for v in outputs if v.type == "Integer"]
        node = nodes[name] = Node(name, instance, instance.stepper(), block(name, state),
                                  block(name, ft), block(name, ints))
        vrs = [instance.vr(v) for v in state + ft]
        node.read_state = instance.reader(vrs[:len(state)]) if state else None
        node.read_feedthrough = instance.reader(vrs[len(state):]) if ft else None
        node.read_outputs = instance.reader(vrs) if vrs else None
        node.read_integers = instance.integer_reader([instance.vr(v) for v in ints]) \
            if ints else None
    for name, node in nodes.items():
        incoming = [c for c in connections if c.end_element == name]
        node.inputs = block(name, [c.end_connector for c in incoming])
        if incoming:
            sources = [columns.index(f"{c.start_element}.{c.start_connector}")
                       for c in incoming]
            vrs = [instances[name].vr(c.end_connector) for c in incoming]
            node.apply_inputs = _input_applier(instances[name], vrs, sources, node.inputs,
                                               verify_inputs)
    return columns, nodes


def _input_applier(instance: Instance, vrs: list[int], sources: list[int], inputs: slice,
                   verify: bool) -> Callable[[list[float]], None]:
    write, read_back = instance.writer(vrs), instance.reader(vrs)
    gather = itemgetter(*sources) if len(sources) > 1 else (lambda v, i=sources[0]: (v[i],))

    def apply(values: list[float]) -> None:
        sent = gather(values)
        write(sent)
        values[inputs] = read_back() if verify else sent
    return apply
