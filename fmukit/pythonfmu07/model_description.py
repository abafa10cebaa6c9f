"""What pythonfmu 0.7 leaves out of modelDescription.xml, added from the variables' declarations.

Units (with degree display units for angles), ``min``/``max``, start values in
their shortest exact form, ``<UnitDefinitions>``, and a complete
``<ModelStructure>``: outputs with their ``dependencies`` (so masters see which
outputs are not direct feedthrough) and ``<InitialUnknowns>``.
"""
from __future__ import annotations

import math
from xml.etree.ElementTree import Element, SubElement

from ..units import DISPLAY_UNIT, unit_definitions
from ..variables import Var


def complete(root: Element, variables: tuple[Var, ...]) -> Element:
    """Complete pythonfmu's model description ``root`` of a slave with these variables."""
    index = {v.name: i + 1 for i, v in enumerate(variables)}
    for element, var in zip(root.find("ModelVariables"), variables):
        if var.kind is str:
            continue
        typed = element.find("Real" if var.is_real else "Integer")
        if var.is_real:
            if var.start is not None:
                typed.set("start", repr(float(var.start)))   # shortest exact form
            typed.set("unit", var.unit)
            if var.unit in DISPLAY_UNIT:
                typed.set("displayUnit", DISPLAY_UNIT[var.unit])
        for bound in ("min", "max"):
            value = getattr(var, bound)
            if math.isfinite(value):
                typed.set(bound, repr(var.kind(value)))
    used = {v.unit for v in variables if v.is_real}
    root.insert(list(root).index(root.find("CoSimulation")) + 1, unit_definitions(used))

    structure = root.find("ModelStructure")
    structure.clear()
    outputs = [v for v in variables if v.causality == "output"]
    if outputs:
        causality = {v.name: v.causality for v in variables}
        listed = SubElement(structure, "Outputs")
        for v in outputs:
            inputs = [d for d in v.depends if causality[d] == "input"]
            SubElement(listed, "Unknown", index=str(index[v.name]),
                       dependencies=_indices(inputs, index))
        initial = SubElement(structure, "InitialUnknowns")
        for v in outputs:
            SubElement(initial, "Unknown", index=str(index[v.name]),
                       dependencies=_indices(v.depends + v.initial_depends, index))
    return root


def _indices(names: tuple[str, ...] | list[str], index: dict[str, int]) -> str:
    """Ordered, space-separated 1-based indices, as ModelStructure wants them."""
    return " ".join(str(i) for i in sorted(index[n] for n in names))
