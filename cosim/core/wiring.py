"""How the components of a system connect: checks, the Gauss-Seidel order, the loop's layout
(a ``Node`` per component) and the coupling algorithms that step it."""
from __future__ import annotations

from dataclasses import dataclass
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
            try:
                variable = instances[element].variable(connector)
            except ValueError as error:
                raise WiringError(f"connection {c}: {error}") from None
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
    """One component as the loop sees it: its output columns and prepared calls (or None)."""
    step: Callable[[float, float], None]
    state: slice                        # Real outputs, no feedthrough
    feedthrough: slice                  # Real outputs, with feedthrough
    integers: slice                     # Integer outputs
    read_state: Callable[[], list[float]] | None = None
    read_feedthrough: Callable[[], list[float]] | None = None
    read_outputs: Callable[[], list[float]] | None = None   # state and feedthrough at once
    read_integers: Callable[[], list[int]] | None = None
    apply_inputs: Callable[[list[float]], None] | None = None  # values -> this node's inputs

    @property
    def outputs(self) -> slice:
        return slice(self.state.start, self.feedthrough.stop)


def layout(instances: dict[str, Instance], connections: list[Connection]
           ) -> tuple[list[str], dict[str, Node]]:
    """(columns, nodes by name): every output, then every connected input, per component;
    ``apply_inputs(values)`` sets a node's inputs from their sources and records them as sent."""
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
        node = nodes[name] = Node(instance.stepper(), block(name, state), block(name, ft),
                                  block(name, ints))
        vrs = [instance.vr(v) for v in state + ft]
        node.read_state = instance.reader(vrs[:len(state)]) if state else None
        node.read_feedthrough = instance.reader(vrs[len(state):]) if ft else None
        node.read_outputs = instance.reader(vrs) if vrs else None
        node.read_integers = instance.reader([instance.vr(v) for v in ints], "Integer") \
            if ints else None
    for name, node in nodes.items():
        incoming = [c for c in connections if c.end_element == name]
        inputs = block(name, [c.end_connector for c in incoming])
        if incoming:
            sources = [columns.index(f"{c.start_element}.{c.start_connector}")
                       for c in incoming]
            write = instances[name].writer([instances[name].vr(c.end_connector)
                                            for c in incoming])
            node.apply_inputs = _input_applier(write, sources, inputs)
    return columns, nodes


def _input_applier(write: Callable[[list[float]], None], sources: list[int],
                   inputs: slice) -> Callable[[list[float]], None]:
    gather = itemgetter(*sources) if len(sources) > 1 else (lambda v, i=sources[0]: (v[i],))

    def apply(values: list[float]) -> None:
        sent = gather(values)
        write(sent)
        values[inputs] = sent
    return apply


# A coupling algorithm does one communication step from the nodes, the values (one per
# column), t_k and h: after it ``values`` holds every signal at t_k and, if ``step``, every
# FMU is at t_k + h.
def gauss_seidel(nodes: list[Node], values: list[float], t: float, h: float,
                 step: bool) -> None:
    """Outputs without feedthrough (the ship's states) at t_k, then each FMU in signal-flow
    order (the paper's guidance -> autopilot -> ship) takes inputs, gives outputs, steps."""
    for node in nodes:
        if node.read_state:
            values[node.state] = node.read_state()
    for node in nodes:
        if node.apply_inputs:
            node.apply_inputs(values)
        if node.read_feedthrough:
            values[node.feedthrough] = node.read_feedthrough()
        if node.read_integers:
            values[node.integers] = node.read_integers()
        if step:
            node.step(t, h)


def jacobi(nodes: list[Node], values: list[float], t: float, h: float, step: bool) -> None:
    """All outputs as they stand, then all inputs, then all FMUs step (OSP libcosim's and
    ecos's): a feedthrough signal arrives one step later per feedthrough FMU."""
    for node in nodes:
        if node.read_outputs:
            values[node.outputs] = node.read_outputs()
        if node.read_integers:
            values[node.integers] = node.read_integers()
    for node in nodes:
        if node.apply_inputs:
            node.apply_inputs(values)
    if step:
        for node in nodes:
            node.step(t, h)


COUPLINGS = {"gauss-seidel": gauss_seidel, "jacobi": jacobi}


def settle(nodes: list[Node], columns: int) -> None:
    """Initial outputs propagated along the connections: enough passes for any acyclic chain."""
    values = [0.0] * columns
    for _ in nodes:
        for node in nodes:
            if node.read_outputs:
                values[node.outputs] = node.read_outputs()
            if node.apply_inputs:
                node.apply_inputs(values)
