"""What pythonfmu3 0.3.4 leaves out of modelDescription.xml, added from the declarations:
``<UnitDefinitions>`` (else fmpy refuses the units), display units, min/max, exact starts
(it writes 16 digits), and dependencies (its bare ``<Output>`` says every output depends on
every input: an algebraic loop to a master). ``time`` (value reference 0) is moved last,
so an importer reading dependencies as 1-based indices (OMSimulator) reads them right.
"""
from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement

from .. import description
from ..description import dependencies
from ..variables import Var


def complete(root: Element, variables: tuple[Var, ...], vr: dict[str, int]) -> Element:
    """Complete pythonfmu3's model description ``root`` of a slave with these variables;
    ``vr``: each one's value reference."""
    listed = root.find("ModelVariables")
    elements = {e.get("name"): e for e in listed}
    for independent in [e for e in listed if e.get("causality") == "independent"]:
        listed.remove(independent)
        listed.append(independent)
    structure, outputs = description.complete(root, variables,
                                              [elements[v.name] for v in variables])
    for tag, when in (("Output", 0), ("InitialUnknown", 1)):
        for v in outputs:
            SubElement(structure, tag, _unknown(vr[v.name], dependencies(v, variables)[when], vr))
    return root


def _unknown(reference: int, names: list[str], vr: dict[str, int]) -> dict[str, str]:
    """An unknown's attributes: its value reference and those it depends on, ordered."""
    references = sorted(vr[n] for n in names)
    attributes = {"valueReference": str(reference),
                  "dependencies": " ".join(map(str, references))}
    if references:
        attributes["dependenciesKind"] = " ".join("dependent" for _ in references)
    return attributes
