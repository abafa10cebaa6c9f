"""Coupling algorithms: how one communication step exchanges signals and steps the FMUs.

Each takes the nodes (``cosim.core.wiring``), the list of current values (one per
column), the communication point t_k and the step h. On return ``values`` holds
every signal at t_k, and, if ``step`` is true, every FMU has stepped to t_k + h
(the last communication point is only sampled).

- ``gauss_seidel`` visits the FMUs in the order given, along the signal flow
  (``wiring.feedthrough_order``): outputs without feedthrough (the ship's states)
  are read at t_k before anyone is visited; then each FMU gets its inputs, gives
  its feedthrough outputs and steps, so the next one sees them at t_k. On the
  paper's diagram: guidance -> autopilot -> ship, as in its Simulink model.
- ``jacobi`` reads every FMU's outputs as they stand after the previous step,
  then sets every input, then steps them all (what OSP libcosim and ecos do). A
  direct-feedthrough signal (the rudder command) reaches its target one step
  later than in Gauss-Seidel, for each feedthrough FMU on its way.
"""
from __future__ import annotations

from typing import Callable

from .wiring import Node

Coupling = Callable[[list[Node], list[float], float, float, bool], None]


def gauss_seidel(nodes: list[Node], values: list[float], t: float, h: float,
                 step: bool) -> None:
    """Each FMU in turn: inputs at t_k, feedthrough outputs at t_k, step."""
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
    """All outputs as they stand, then all inputs, then all FMUs step."""
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
