"""Coupling algorithms: one communication step from the nodes (``wiring``), the values (one
per column), t_k and h; after it ``values`` holds every signal at t_k and, if ``step``,
every FMU is at t_k + h."""
from __future__ import annotations

from typing import Callable

from .wiring import Node

Coupling = Callable[[list[Node], list[float], float, float, bool], None]


def gauss_seidel(nodes: list[Node], values: list[float], t: float, h: float,
                 step: bool) -> None:
    """Outputs without feedthrough (the ship's states) at t_k, then each FMU in signal-flow
    order gets its inputs, gives its feedthrough outputs and steps (the paper's guidance ->
    autopilot -> ship, as in its Simulink model)."""
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


COUPLINGS: dict[str, Coupling] = {"gauss-seidel": gauss_seidel, "jacobi": jacobi}


def settle(nodes: list[Node], columns: int) -> None:
    """Initial outputs propagated along the connections: enough passes for any acyclic chain."""
    values = [0.0] * columns
    for _ in nodes:
        for node in nodes:
            if node.read_outputs:
                values[node.outputs] = node.read_outputs()
            if node.apply_inputs:
                node.apply_inputs(values)
