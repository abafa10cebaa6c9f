"""What pythonfmu 0.7 leaves out of modelDescription.xml, added from the declarations: units,
display units, min/max, exact starts, ``<UnitDefinitions>`` and a complete
``<ModelStructure>`` (dependencies by 1-based index).
"""
from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement

from ..description import dependencies, typed_attributes, units_used
from ..units import unit_definitions
from ..variables import Var


def complete(root: Element, variables: tuple[Var, ...]) -> Element:
    """Complete pythonfmu's model description ``root`` of a slave with these variables."""
    index = {v.name: i + 1 for i, v in enumerate(variables)}
    for element, var in zip(root.find("ModelVariables"), variables):
        if var.kind is not str:
            element.find("Real" if var.is_real else "Integer").attrib.update(
                typed_attributes(var))
    root.insert(list(root).index(root.find("CoSimulation")) + 1,
                unit_definitions(units_used(variables)))

    structure = root.find("ModelStructure")
    structure.clear()
    outputs = [v for v in variables if v.causality == "output"]
    if outputs:
        listed = SubElement(structure, "Outputs")
        for v in outputs:
            SubElement(listed, "Unknown", index=str(index[v.name]),
                       dependencies=_indices(dependencies(v, variables)[0], index))
        initial = SubElement(structure, "InitialUnknowns")
        for v in outputs:
            SubElement(initial, "Unknown", index=str(index[v.name]),
                       dependencies=_indices(dependencies(v, variables)[1], index))
    return root


def _indices(names: list[str], index: dict[str, int]) -> str:
    """Ordered, space-separated 1-based indices, as ModelStructure wants them."""
    return " ".join(str(i) for i in sorted(index[n] for n in names))
