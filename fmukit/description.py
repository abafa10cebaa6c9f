"""What a variable's declaration says in modelDescription.xml, the same in FMI 2.0 and 3.0:
its type's attributes (start in its shortest exact form, unit and display unit, min and
max), the units used and each output's dependencies. Each adapter's ``model_description``
puts them where its version wants them.
"""
from __future__ import annotations

import math
from xml.etree.ElementTree import Element

from .units import DISPLAY_UNIT, unit_definitions
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


def complete(root: Element, variables: tuple[Var, ...],
             typed: list[Element | None]) -> tuple[Element, list[Var]]:
    """Add each numeric variable's attributes to its ``typed`` element and the
    <UnitDefinitions> to ``root``; the emptied <ModelStructure>, and the outputs."""
    for element, var in zip(typed, variables):
        if var.kind is not str:
            element.attrib.update(typed_attributes(var))
    root.insert(list(root).index(root.find("CoSimulation")) + 1,
                unit_definitions({v.unit for v in variables if v.is_real}))
    structure = root.find("ModelStructure")
    structure.clear()
    return structure, [v for v in variables if v.causality == "output"]
