"""Units: the one a model variable declares, and the units a Real given as text may carry
('40deg', '0.3m/s'), with each one's factor to the declared unit."""
from __future__ import annotations

import math
import re
from typing import Any, Mapping

DECIMAL = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
UNITS = {"rad": {"rad": 1.0, "deg": math.pi / 180},         # by the unit declared
         "rad/s": {"rad/s": 1.0, "deg/s": math.pi / 180},
         "rad/s^2": {"rad/s^2": 1.0, "deg/s^2": math.pi / 180},
         "m/s": {"m/s": 1.0, "kn": 1852 / 3600, "km/h": 1 / 3.6},
         "m": {"m": 1.0, "cm": 0.01, "mm": 0.001, "km": 1000.0},
         "s": {"s": 1.0, "min": 60.0, "h": 3600.0},
         "rev/s": {"rev/s": 1.0, "rpm": 1 / 60}}
_KNOWN = {unit for units in UNITS.values() for unit in units}
_WITH_UNIT = re.compile(rf"\s*({DECIMAL.pattern})\s*((?![eE][+-]?[0-9])[A-Za-z][A-Za-z/^0-9]*)\s*")


def unit_of(variable: Any) -> str:
    """The unit a model variable declares, its own or its declared type's ("" for none)."""
    return variable.unit or getattr(variable.declaredType, "unit", None) or ""


def in_unit(declared: str | None, text: str) -> tuple[str, float] | None:
    """(the number's text, its factor to ``declared``) of a Real's text with a unit ('40deg'),
    None if it has none or is no Real's (``declared`` None); ValueError naming those it
    may carry."""
    found = _WITH_UNIT.fullmatch(text) if declared is not None else None
    if found is None or found[2] not in _KNOWN | {declared}:         # '0x10': no unit
        return None
    units = UNITS.get(declared, {declared: 1.0} if declared else {})
    if found[2] not in units:
        may = " or ".join(units) if units else "no unit (it declares none)"
        raise ValueError(f"carries the unit {found[2]!r}; it takes {may}")
    return found[1], units[found[2]]


def unit_notes(units: Mapping[str, Mapping[str, str]], given: Mapping[str, Mapping[str, Any]],
               taken: Mapping[str, Mapping[str, Any]]) -> list[str]:
    """What a user should know of values given (``units``: each variable's declared): one
    with a unit, as converted; an angle given without one, past a full turn, as taken."""
    notes = []
    for component, values in given.items():
        for name, raw in values.items():
            unit, value = units[component][name], taken[component][name]
            if isinstance(raw, str) and _WITH_UNIT.fullmatch(raw):
                notes.append(f"{component}.{name} = {raw.strip()} is {value!r} {unit}")
            elif unit in ("rad", "rad/s") and isinstance(value, float) and \
                    abs(value) > 2 * math.pi:
                deg = unit.replace("rad", "deg")
                notes.append(f"{component}.{name} = {value!r} is taken in {unit} "
                             f"({math.degrees(value):.6g} {deg}); for degrees write "
                             f"{value!r}{deg}")
    return notes
