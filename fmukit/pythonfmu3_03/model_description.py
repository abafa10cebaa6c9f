"""What pythonfmu3 0.3.4 leaves out of modelDescription.xml, added from the declarations:
``<UnitDefinitions>`` (else fmpy refuses the units), display units, min/max, exact starts
(it writes 16 digits), and dependencies (its bare ``<Output>`` says every output depends on
every input: an algebraic loop to a master). ``time`` (value reference 0) is moved last,
so an importer reading dependencies as 1-based indices (OMSimulator) reads them right.
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
