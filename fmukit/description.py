"""What a variable's declaration says in modelDescription.xml, the same in FMI 2.0 and 3.0.

Each adapter's ``model_description`` completes what its pythonfmu writes from these:
the attributes of a numeric variable's type (start in its shortest exact form, for
pythonfmu3 writes 16 digits, and 0.1 + 0.2 as 0.3; unit and display unit; min and max),
the ``<UnitDefinitions>`` of the units used (``fmukit.units``), and the variables each
output depends on, at every step and at initialisation. Only where they go differs:
FMI 2.0 puts the attributes on a variable's ``<Real>`` or ``<Integer>`` and lists
dependencies by 1-based index; FMI 3.0 puts them on its ``<Float64>`` or ``<Int32>``
and lists dependencies by value reference.
"""
from __future__ import annotations

import math

from .units import DISPLAY_UNIT
from .variables import Var


def typed_attributes(var: Var) -> dict[str, str]:
    """The attributes of a numeric variable's type, in the order they are written."""
    attributes = {}
    if var.is_real:
        if var.start is not None:
            attributes["start"] = repr(float(var.start))    # shortest exact form
        attributes["unit"] = var.unit
        if var.unit in DISPLAY_UNIT:
            attributes["displayUnit"] = DISPLAY_UNIT[var.unit]
    elif var.start is not None:
        attributes["start"] = str(int(var.start))
    for bound in ("min", "max"):
        value = getattr(var, bound)
        if math.isfinite(value):
            attributes[bound] = repr(var.kind(value))
    return attributes


def dependencies(output: Var, variables: tuple[Var, ...]) -> tuple[list[str], list[str]]:
    """The variables ``output`` depends on while stepping (its inputs: direct feedthrough)
    and at initialisation (inputs and parameters, and its further knowns then)."""
    causality = {v.name: v.causality for v in variables}
    return ([d for d in output.depends if causality[d] == "input"],
            list(output.depends + output.initial_depends))


def units_used(variables: tuple[Var, ...]) -> set[str]:
    """The units of the Real variables."""
    return {v.unit for v in variables if v.is_real}
