"""Values for FMU variables, checked before any FMU call: exactly what the FMI 2.0 call carries
(section 2.1.2), within the declaration (2.2.7), settable in initialisation mode (4.2.4)."""
from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any, Iterable, Mapping

from fmpy.model_description import ModelDescription

from .system import SystemDescription, close_matches, did_you_mean
from .units import DECIMAL as _DECIMAL, in_unit, unit_of

INTEGER_RANGE = (-2**31, 2**31 - 1)                 # fmi2Integer, a C int

Value = bool | int | float | str

_SPECIAL = re.compile(r"[+-]?(?:inf|infinity|nan)", re.IGNORECASE)
_BOOLEAN = {"true": True, "1": True, "false": False, "0": False}
_TAKES = {"Real": "a Real (a double)", "Integer": "an Integer, a whole number from "
          f"{INTEGER_RANGE[0]} to {INTEGER_RANGE[1]}",
          "Boolean": "a Boolean: true, false, 1 or 0",
          "String": "a String: UTF-8 text without NUL"}


@dataclass(frozen=True)
class Declaration:
    """What an FMU declares of one variable (section 2.2.7); items: (name, value)."""
    name: str
    type: str
    causality: str = "parameter"
    variability: str = "fixed"
    initial: str | None = "exact"
    min: float | int | None = None
    max: float | int | None = None
    items: tuple[tuple[str, int], ...] = ()
    unit: str = ""                                  # its own or its declared type's

    @property
    def settable(self) -> bool:                     # in initialisation mode (section 4.2.4)
        return self.causality == "input" or (self.variability != "constant"
                                             and self.initial == "exact")

    def takes(self) -> str:
        """What it takes, in words: 'a finite Real, from 0.0 to 0.1'."""
        if self.type == "Enumeration":
            return "an Enumeration item: " + ", ".join(f"{v} ({n})" for n, v in self.items)
        if self.type == "Integer":
            low = INTEGER_RANGE[0] if self.min is None else max(INTEGER_RANGE[0], self.min)
            high = INTEGER_RANGE[1] if self.max is None else min(INTEGER_RANGE[1], self.max)
            return f"an Integer, a whole number from {low} to {high}"
        if self.type != "Real":
            return _TAKES[self.type]
        infinite = self.max == math.inf or self.min == -math.inf
        kind = "a Real, not NaN" if infinite else "a finite Real"
        low, high = (None if b is None or math.isinf(b) else b for b in (self.min, self.max))
        if low is not None and high is not None:
            return f"{kind}, from {low!r} to {high!r}"
        if low is not None or high is not None:
            return f"{kind}, {'>=' if high is None else '<='} {low if high is None else high!r}"
        return kind


def declarations(description: ModelDescription) -> dict[str, Declaration]:
    """Every variable's declaration, min and max its own or else its declared type's."""
    out = {}
    for v in description.modelVariables:
        declared, number = v.declaredType, float if v.type == "Real" else int
        bounds = (getattr(v, bound, None) or getattr(declared, bound, None)
                  for bound in ("min", "max"))
        items = tuple((i.name, int(i.value)) for i in getattr(declared, "items", None) or ())
        out[v.name] = Declaration(v.name, v.type, v.causality, v.variability, v.initial,
                                  *(None if b is None else number(b) for b in bounds), items,
                                  unit_of(v))
    return out


def fmi_value(target: str, type_name: str, value: Any,
              declaration: Declaration | None = None) -> Value:
    """``value`` exactly as the FMI 2.0 call of ``type_name`` carries it (and within
    ``declaration``), or ValueError naming ``target``, the value and what it takes."""
    carry = _CARRIED.get(type_name)
    if carry is None:
        raise ValueError(f"{target} is of type {type_name!r}, which FMI 2.0 does not have")
    try:
        exact = carry(value)
        if declaration is not None:
            _within(declaration, exact)
    except ValueError as refusal:           # why: 'is not a whole number'
        takes = declaration.takes() if declaration else _TAKES[type_name]
        raise ValueError(f"{target} = {value!r} {refusal}; {target} is {takes}") from None
    return exact


def checked(component: str, declaration: Declaration, value: Any) -> Value:
    """The exact value to set for ``component``'s variable so declared, or ValueError."""
    items = dict(declaration.items)
    if isinstance(value, str) and value.strip() in items:
        return items[value.strip()]
    if isinstance(value, str):
        try:
            found = in_unit(declaration.unit if declaration.type == "Real" else None, value)
        except ValueError as refusal:
            raise ValueError(f"{component}.{declaration.name} = {value!r} {refusal}") from None
        value = value if found is None else _real(found[0]) * found[1]
    kind = "Integer" if declaration.type == "Enumeration" else declaration.type
    return fmi_value(f"{component}.{declaration.name}", kind, value, declaration)


def _within(declaration: Declaration, value: Value) -> None:
    """Within min and max (+-inf only where declared so), an Enumeration's items."""
    if declaration.type == "Real" and math.isnan(value):
        raise ValueError("is not a number (NaN)")
    if declaration.type == "Real" and math.isinf(value) and \
            value != (declaration.max if value > 0 else declaration.min):
        raise ValueError("is not finite")
    low, high = declaration.min, declaration.max
    if (low is not None and value < low) or (high is not None and value > high):
        raise ValueError("is outside its declared range")
    if declaration.items and value not in dict(declaration.items).values():
        raise ValueError("is not one of its items")


def setting(component: str, path: str | Path, declared: dict[str, Declaration], name: str,
            value: Any, elsewhere: Mapping[str, Iterable[str]] | None = None) -> Value:
    """``checked`` for the variable ``name`` of ``component`` (its FMU at ``path``), which must
    exist and be settable; ValueError naming what it has (and which of ``elsewhere`` has it)."""
    if name not in declared:
        raise no_variable(component, path, declared, name, elsewhere)
    declaration = declared[name]
    if not declaration.settable:
        causality, initial = declaration.causality, declaration.initial
        kind = (f"a {declaration.variability} {causality}"
                if declaration.variability == "constant" else
                f"{'an' if causality[0] in 'aeiou' else 'a'} {causality}"
                f"{f' (initial {initial})' if initial else ''}")
        names = [n for n, d in declared.items() if d.settable]
        raise ValueError(f"{component}.{name} cannot be set: it is {kind}; FMU "
                         f"'{component}' ({Path(path).name}) takes values for "
                         f"{', '.join(names) or 'no variable'}")
    return checked(component, declaration, value)


def no_variable(component: str, path: str | Path, names: Iterable[str], name: str,
                elsewhere: Mapping[str, Iterable[str]] | None = None) -> ValueError:
    """The error for a variable the FMU does not have: those it has, and the closest of them
    or else one of that name (but for case) of another component (``elsewhere``)."""
    names = list(names)
    others = [f"{c}.{n}" for c, theirs in (elsewhere or {}).items() for n in theirs
              if n.lower() == name.lower()]
    return ValueError(f"FMU '{component}' ({Path(path).name}) has no variable '{name}'; "
                      f"it has: {', '.join(names)}"
                      f"{did_you_mean(close_matches(name, names) or others)}")


def _real(value: Any) -> float:
    if isinstance(value, str):
        text = value.strip()
        if _SPECIAL.fullmatch(text):
            return float(text)
        if not _DECIMAL.fullmatch(text):
            raise ValueError("is not a number")
        number = float(text)
        if math.isinf(number):
            raise ValueError("is beyond the range of a double")
        if number == 0 and Decimal(text) != 0:
            raise ValueError("is below the smallest double (it would be set as 0)")
        return number
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError("is not a number")
    try:
        number = float(value)
    except OverflowError:
        raise ValueError("is beyond the range of a double") from None
    if number != value and not math.isnan(number):
        raise ValueError(f"has no exact double (the nearest is {number!r})")
    return number


def _integer(value: Any) -> int:
    if isinstance(value, str) and _DECIMAL.fullmatch(value.strip()):
        exact = Decimal(value.strip())
    elif isinstance(value, numbers.Real) and not isinstance(value, bool):
        exact = Decimal(int(value) if isinstance(value, numbers.Integral) else float(value))
    else:
        raise ValueError("is not a whole number")
    if not exact.is_finite() or exact != exact.to_integral_value():
        raise ValueError("is not a whole number")
    if not INTEGER_RANGE[0] <= exact <= INTEGER_RANGE[1]:
        raise ValueError("is outside the range of an FMI Integer (32 bits)")
    return int(exact)


def _boolean(value: Any) -> bool:
    if isinstance(value, str) and value.strip().lower() in _BOOLEAN:
        return _BOOLEAN[value.strip().lower()]
    if isinstance(value, numbers.Integral) and value in (0, 1):
        return bool(value)
    raise ValueError("is not a Boolean")


def _string(value: Any) -> str:
    if not isinstance(value, str):
        raise ValueError("is not text")
    if "\0" in value:
        raise ValueError("holds a NUL character, where an FMI string ends")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise ValueError("is not encodable as UTF-8") from None
    return value


_CARRIED = {"Real": _real, "Integer": _integer, "Boolean": _boolean, "String": _string}


def parameters(system: SystemDescription, paths: dict[str, Path],
               declared: dict[str, dict[str, Declaration]],
               overrides: Mapping[str, Mapping[str, Any]] | None = None
               ) -> tuple[dict[str, dict[str, Value]], dict[str, dict[str, Value]]]:
    """(the system's bindings updated by ``overrides``, the overrides alone), by component, as
    ``setting`` returns them; ValueError naming the value (and the .ssd, for a binding)."""
    if not isinstance(overrides or {}, Mapping):
        raise ValueError(f"set: overrides must map component names to their values, got "
                         f"{overrides!r}")
    for component, values in (overrides or {}).items():
        if not isinstance(values, Mapping):
            raise ValueError(f"set: the values for '{component}' must map variable names to "
                             f"values, got {values!r}")
    given = {component: dict(values) for component, values in (overrides or {}).items()}
    connected = {(c.end_element, c.end_connector): f"{c.start_element}.{c.start_connector}"
                 for c in system.connections}
    settable = {c: [n for n, d in theirs.items() if d.settable] for c, theirs in declared.items()}
    result: dict[str, dict[str, Value]] = {}
    for component, values in system.parameters(given).items():
        result[component] = {}
        elsewhere = {c: names for c, names in settable.items() if c != component}
        for name, value in values.items():
            try:
                if (component, name) in connected:
                    raise ValueError(f"{component}.{name} is an input that the connection "
                                     f"from {connected[component, name]} sets")
                result[component][name] = setting(component, paths[component],
                                                  declared[component], name, value, elsewhere)
            except ValueError as error:
                if name in given.get(component, {}):
                    raise
                raise ValueError(f"{system.path or system.name}: parameter binding "
                                 f"{error}") from None
    return result, {c: {n: result[c][n] for n in v} for c, v in given.items()}
