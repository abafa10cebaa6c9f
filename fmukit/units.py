"""SI units at the FMU interfaces, as <UnitDefinitions>: each unit's base-unit exponents (kg,
m, s, rad), factor and display units.
"""
from __future__ import annotations

import math
from xml.etree.ElementTree import Element, SubElement

# name: (base-unit exponents, factor, display units {name: factor})
UNITS: dict[str, tuple[dict[str, int], float, dict[str, float]]] = {
    "1": ({}, 1.0, {}),
    "m": ({"m": 1}, 1.0, {}),
    "m/s": ({"m": 1, "s": -1}, 1.0, {}),
    "s": ({"s": 1}, 1.0, {}),
    "1/s": ({"s": -1}, 1.0, {}),
    "rad": ({"rad": 1}, 1.0, {"deg": 180.0 / math.pi}),
    "rad/s": ({"rad": 1, "s": -1}, 1.0, {"deg/s": 180.0 / math.pi}),
    "rad/s2": ({"rad": 1, "s": -2}, 1.0, {"deg/s2": 180.0 / math.pi}),
    "rad.s": ({"rad": 1, "s": 1}, 1.0, {"deg.s": 180.0 / math.pi}),
    "deg": ({"rad": 1}, math.pi / 180.0, {}),
    "deg/s": ({"rad": 1, "s": -1}, math.pi / 180.0, {}),
    "rev/s": ({"rad": 1, "s": -1}, 2.0 * math.pi, {"rpm": 60.0}),
    "N": ({"kg": 1, "m": 1, "s": -2}, 1.0, {}),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, 1.0, {}),
}

DISPLAY_UNIT = {"rad": "deg", "rad/s": "deg/s", "rad/s2": "deg/s2"}
"""Display unit a variable of this unit shows by default."""


def unit_definitions(used: set[str]) -> Element:
    """<UnitDefinitions> for the units in ``used``."""
    root = Element("UnitDefinitions")
    for name in sorted(used):
        exponents, factor, display = UNITS[name]
        unit = SubElement(root, "Unit", name=name)
        base = {k: str(v) for k, v in exponents.items()}
        if factor != 1.0:
            base["factor"] = repr(factor)
        SubElement(unit, "BaseUnit", base)
        for display_name, display_factor in display.items():
            SubElement(unit, "DisplayUnit", name=display_name, factor=repr(display_factor))
    return root
