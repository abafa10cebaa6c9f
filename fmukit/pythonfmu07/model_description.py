"""What pythonfmu 0.7 leaves out of modelDescription.xml, added from the declarations: units,
display units, min/max, exact starts, ``<UnitDefinitions>`` and a complete
``<ModelStructure>`` (dependencies by 1-based index).
"""
from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement

from .. import description
from ..description import dependencies
from ..variables import Var


def complete(root: Element, variables: tuple[Var, ...]) -> Element:
    """Complete pythonfmu's model description ``root`` of a slave with these variables."""
    index = {v.name: i + 1 for i, v in enumerate(variables)}
    structure, outputs = description.complete(root, variables, [
        e.find("Real" if v.is_real else "Integer")
        for e, v in zip(root.find("ModelVariables"), variables)])
    for tag, when in (("Outputs", 0), ("InitialUnknowns", 1)) if outputs else ():
        listed = SubElement(structure, tag)
        for v in outputs:
            SubElement(listed, "Unknown", index=str(index[v.name]),
                       dependencies=_indices(dependencies(v, variables)[when], index))
    return root


def _indices(names: list[str], index: dict[str, int]) -> str:
    """Ordered, space-separated 1-based indices, as ModelStructure wants them."""
    return " ".join(str(i) for i in sorted(index[n] for n in names))
