"""The autopilot port contract: inputs ``psi`` (rad), ``r`` (rad/s), ``psi_d`` (rad); output
``delta_c`` (rad), positive turning the ship to port. An autopilot written with fmukit declares
``variables = (*INPUTS, rudder_command(depends=..., get=...), ...)``."""
from __future__ import annotations

from typing import Any, Callable

from .variables import Var

INPUTS = (
    Var.input("psi", 0.0, "rad", "ship heading"),
    Var.input("r", 0.0, "rad/s", "ship yaw rate", -100.0, 100.0),
    Var.input("psi_d", 0.0, "rad", "desired course"),
)


def rudder_command(depends: tuple[str, ...], get: Callable[[Any], float],
                   description: str = "commanded rudder angle; positive turns the ship to "
                                      "port") -> Var:
    """The output ``delta_c``, evaluated by ``get`` from the inputs and parameters it depends on."""
    return Var.output("delta_c", "rad", description, depends=depends, get=get)


PORTS = (*INPUTS, rudder_command((), lambda slave: 0.0))    # what a user's autopilot must have
