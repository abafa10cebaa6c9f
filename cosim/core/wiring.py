"""How the components of a system connect: checks, the Gauss-Seidel order, the loop's layout
(a ``Node`` per component) and the coupling algorithms that step it."""
from __future__ import annotations

from dataclasses import dataclass, field
from graphlib import CycleError, TopologicalSorter
from operator import itemgetter
from typing import Callable

from .instance import Instance
from .system import PORT_NAME, Connection, SystemDescription


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
    """One component as the loop sees it: its columns and prepared calls (or None), and the
    two it takes part in a communication step with (``start``, ``exchange``; ``couple``)."""
    state: slice                        # Real outputs, no feedthrough
    feedthrough: slice                  # Real outputs, with feedthrough
    integers: slice                     # Integer outputs
    name: str = ""
    inputs: slice = field(default_factory=lambda: slice(0))     # connected inputs, as sent
    sources: list[int] = field(default_factory=list)    # the column feeding each input
    input_names: list[str] = field(default_factory=list)    # their columns' names
    modifiers: dict[int, Callable[[float], float]] = field(default_factory=dict)  # by events
    vrs: list[int] = field(default_factory=list)        # of the outputs, then the inputs
    read_state: Callable[[], list[float]] | None = None
    read_feedthrough: Callable[[], list[float]] | None = None
    read_outputs: Callable[[], list[float]] | None = None   # state and feedthrough at once
    read_integers: Callable[[], list[int]] | None = None
    apply_inputs: Callable[[list[float]], None] | None = None  # values -> this node's inputs
    start: Callable[[list], None] = lambda values: None
    exchange: Callable[[list, float, float, bool], None] = lambda values, t, h, step: None

    @property
    def outputs(self) -> slice:
        return slice(self.state.start, self.feedthrough.stop)

    def phases(self, gauss_seidel: bool) -> tuple[slice, slice]:
        """(the outputs read as a step starts, those read once its inputs are set)."""
        if gauss_seidel:
            return self.state, slice(self.feedthrough.start, self.integers.stop)
        end = self.integers.stop
        return slice(self.state.start, end), slice(end, end)


def layout(instances: dict[str, Instance], connections: list[Connection],
           gauss_seidel: bool = True, calling: list[str | None] | None = None
           ) -> tuple[list[str], dict[str, Node]]:
    """(columns, nodes by name): every output, then every connected input, per component;
    ``apply_inputs(values)`` sets a node's inputs from their sources and records them as sent;
    ``calling[0]``: the component whose calls the loop is in (for a watchdog)."""
    columns: list[str] = []

    def block(name: str, variables: list) -> slice:
        for v in variables:                   # a CSV column's heading, as it is
            if not PORT_NAME.fullmatch(v):
                raise WiringError(f"{name}.{v}: a variable recorded holds no comma, quote, "
                                  "space at either end or control character in its name")
        columns.extend(f"{name}.{v}" for v in variables)
        return slice(len(columns) - len(variables), len(columns))

    nodes = {}
    for name, instance in instances.items():
        outputs = [v for v in instance.variables.values() if v.causality == "output"]
        reals = [v for v in outputs if v.type == "Real"]
        state = [v.name for v in reals if not instance.feedthrough.get(v.name)]
        ft = [v.name for v in reals if instance.feedthrough.get(v.name)]
        ints = [v.name for v in outputs if v.type == "Integer"]
        node = nodes[name] = Node(block(name, state), block(name, ft), block(name, ints), name)
        node.vrs = vrs = [instance.vr(v) for v in state + ft + ints]
        node.read_state = instance.reader(vrs[:len(state)]) if state else None
        node.read_feedthrough = instance.reader(vrs[len(state):len(reals)]) if ft else None
        node.read_outputs = instance.reader(vrs[:len(reals)]) if reals else None
        node.read_integers = instance.reader(vrs[len(reals):], "Integer") if ints else None
    for name, node in nodes.items():
        incoming = [c for c in connections if c.end_element == name]
        node.inputs = block(name, [c.end_connector for c in incoming])
        if incoming:
            node.sources = [columns.index(f"{c.start_element}.{c.start_connector}")
                            for c in incoming]
            node.input_names = columns[node.inputs]
            node.vrs += [instances[name].vr(c.end_connector) for c in incoming]
            write, gather = instances[name].writer(node.vrs[-len(incoming):]), gatherer(node)

            def apply(values: list[float], write=write, gather=gather, inputs=node.inputs):
                sent = gather(values)
                write(sent)
                values[inputs] = sent
            node.apply_inputs = apply
        own = getattr(instances[name], "couple", None)     # an isolated FMU's: one message
        node.start, node.exchange = own(node, gauss_seidel) if own else \
            couple(node, instances[name].stepper(), gauss_seidel, calling or [None])
    return columns, nodes


def gatherer(node: Node) -> Callable[[list[float]], tuple[float, ...]]:
    """The values sent to a node's connected inputs: their sources', or an event's (its
    ``modifiers``, by the input's place)."""
    sources, modifiers = node.sources, node.modifiers
    pick = itemgetter(*sources) if len(sources) > 1 else \
        (lambda v, i=sources[0]: (v[i],)) if sources else (lambda v: ())

    def gather(values: list[float]) -> tuple[float, ...]:
        sent = pick(values)
        return tuple(modifiers[i](s) if i in modifiers else s
                     for i, s in enumerate(sent)) if modifiers else sent
    return gather


def couple(node: Node, step: Callable[[float, float], None], gauss_seidel: bool,
           calling: list[str | None]):
    """(start, exchange) of ``node`` from its prepared calls: Gauss-Seidel's outputs without
    feedthrough as a step starts, its inputs, outputs with feedthrough and step in signal-flow
    order; Jacobi's outputs all as the step starts, its inputs and step after."""
    read_first = node.read_state if gauss_seidel else node.read_outputs
    first = node.state if gauss_seidel else node.outputs
    read_ints, apply, name = node.read_integers, node.apply_inputs, node.name
    read_ft = node.read_feedthrough if gauss_seidel else None

    def start(values: list) -> None:
        calling[0] = name
        if read_first:
            values[first] = read_first()
        if read_ints and not gauss_seidel:
            values[node.integers] = read_ints()

    def exchange(values: list, t: float, h: float, advance: bool) -> None:
        calling[0] = name
        if apply:
            apply(values)
        if read_ft:
            values[node.feedthrough] = read_ft()
        if read_ints and gauss_seidel:
            values[node.integers] = read_ints()
        if advance:
            step(t, h)
    exchange.__code__ = exchange.__code__.replace(co_name=f"exchange_with_{name}")  # named in
    return start, exchange                          # a crash's traceback (faulthandler's)


def communication_step(nodes: list[Node], values: list[float], t: float, h: float,
                       step: bool) -> None:
    """After it ``values`` holds every signal at t_k and, if ``step``, every FMU is at t_k + h.
    Gauss-Seidel (the paper's guidance -> autopilot -> ship, in signal-flow order) or Jacobi
    (OSP libcosim's and ecos's: a feedthrough signal arrives a step later per feedthrough FMU),
    as the nodes were laid out: Jacobi's inputs depend only on outputs read as it starts."""
    for node in nodes:
        node.start(values)
    for node in nodes:
        node.exchange(values, t, h, step)


COUPLINGS = ("gauss-seidel", "jacobi")


def settle(nodes: list[Node], columns: int) -> None:
    """Initial outputs propagated along the connections: enough passes for any acyclic chain."""
    values = [0.0] * columns
    for _ in nodes:
        for node in nodes:
            if node.read_outputs:
                values[node.outputs] = node.read_outputs()
            if node.apply_inputs:
                node.apply_inputs(values)
