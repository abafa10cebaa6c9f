"""What pythonfmu3 0.3.4 leaves out of an FMI 3.0 modelDescription.xml, from the declarations.

pythonfmu3 writes a Float64 with a unit only (no ``<UnitDefinitions>``, so that fmpy's
validator refuses the unit; no display unit, min or max), start values with 16
significant digits (not always the double: 0.1 + 0.2 is written 0.3), an Int32 without
min and max, and a ``<ModelStructure>`` of bare ``<Output>`` and ``<InitialUnknown>``
elements, which say that every output depends on every input: our master, for one,
then finds an algebraic loop in a loop of autopilot and ship. Each is completed from
the declarations (``fmukit.description``), dependencies by value reference.

The independent variable FMI 3.0 requires, ``time`` (``slave.Fmi3Entry``), has value
reference 0 and is moved to the end of ``<ModelVariables>``: the declared variables'
value references are then their 1-based positions, and an importer that reads FMI 3.0
dependencies as FMI 2.0's 1-based indices (OMSimulator) reads them right.
"""
from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement

from ..description import dependencies, typed_attributes, units_used
from ..units import unit_definitions
from ..variables import Var


def complete(root: Element, variables: tuple[Var, ...], vr: dict[str, int]) -> Element:
    """Complete pythonfmu3's model description ``root`` of a slave with these variables;
    ``vr``: each one's value reference."""
    listed = root.find("ModelVariables")
    elements = {e.get("name"): e for e in listed}
    for independent in [e for e in listed if e.get("causality") == "independent"]:
        listed.remove(independent)
        listed.append(independent)
    for var in variables:
        if var.kind is not str:
            elements[var.name].attrib.update(typed_attributes(var))
    cosimulation = root.find("CoSimulation")
    root.insert(list(root).index(cosimulation) + 1, unit_definitions(units_used(variables)))

    structure = root.find("ModelStructure")
    structure.clear()
    outputs = [v for v in variables if v.causality == "output"]
    for v in outputs:
        SubElement(structure, "Output", _unknown(vr[v.name], dependencies(v, variables)[0], vr))
    for v in outputs:
        SubElement(structure, "InitialUnknown",
                   _unknown(vr[v.name], dependencies(v, variables)[1], vr))
    return root


def _unknown(reference: int, names: list[str], vr: dict[str, int]) -> dict[str, str]:
    """An unknown's attributes: its value reference and those it depends on, ordered."""
    references = sorted(vr[n] for n in names)
    attributes = {"valueReference": str(reference),
                  "dependencies": " ".join(map(str, references))}
    if references:
        attributes["dependenciesKind"] = " ".join("dependent" for _ in references)
    return attributes
