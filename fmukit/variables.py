"""``Var``: an FMU variable declared once, the source of its registration, its
modelDescription.xml entry (``describe``) and its range check; the SI units (``UNITS``)."""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any, Callable, Iterable
from xml.etree.ElementTree import Element, SubElement

from .refusals import Refused

# name: (base-unit exponents (kg, m, s, rad), factor, display units {name: factor})
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
DISPLAY_UNIT = {"rad": "deg", "rad/s": "deg/s", "rad/s2": "deg/s2"}     # shown by default


@dataclass(frozen=True)
class Var:
    """One FMU variable, declared once. Build it with the class methods."""
    name: str
    causality: str                    # "parameter" | "input" | "output"
    unit: str = "1"                   # key of UNITS (Real only)
    description: str = ""
    start: float | int | str | None = None
    kind: type = float                # float (Real), int (Integer) or str (String)
    depends: tuple[str, ...] = ()     # outputs: inputs and parameters they depend on
    initial_depends: tuple[str, ...] = ()     # outputs: further knowns, at initialisation only
    get: Callable[[Any], Any] | None = None   # outputs: value from the slave
    min: float = -math.inf            # inputs and parameters: the valid range, written to
    max: float = math.inf             # modelDescription.xml and enforced (NaN is never valid)
    tunable: bool = False             # parameters: settable between steps (a timed event)

    def __post_init__(self) -> None:
        if self.kind is float and self.unit not in UNITS:
            raise ValueError(f"variable {self.name}: unit {self.unit!r} is not one of "
                             f"{', '.join(UNITS)} (fmukit/variables.py)")

    @classmethod
    def parameter(cls, name: str, start: float | int | str, unit: str = "1",
                  description: str = "", min: float = -math.inf,
                  max: float = math.inf, tunable: bool = False) -> Var:
        """A fixed (``tunable``: settable between steps) parameter; its Python type (float,
        int, str) sets the FMI type."""
        return cls(name, "parameter", unit, description, start, type(start), min=min, max=max,
                   tunable=tunable)

    @classmethod
    def input(cls, name: str, start: float, unit: str = "1", description: str = "",
              min: float = -math.inf, max: float = math.inf) -> Var:
        """A continuous Real input."""
        return cls(name, "input", unit, description, float(start), min=min, max=max)

    @classmethod
    def output(cls, name: str, unit: str = "1", description: str = "",
               depends: tuple[str, ...] = (), initial_depends: tuple[str, ...] = (),
               get: Callable[[Any], Any] | None = None, kind: type = float) -> Var:
        """An output read from the slave by ``get`` (default: the model's attribute),
        depending on ``depends`` and, at initialisation only, ``initial_depends``."""
        return cls(name, "output", unit, description, None, kind, depends, initial_depends,
                   get)

    def check(self, value: Any) -> None:
        """Refused naming this variable if a number is NaN, infinite or out of range."""
        if self.kind is str:
            return
        kind = "input" if self.causality == "input" else "parameter"
        if not math.isfinite(value):
            raise Refused(f"{kind} {self.name} = {value} is not finite",
                          "nonfinite_input" if kind == "input" else kind, self.name)
        if not self.min <= value <= self.max:
            raise Refused(f"{kind} {self.name} = {value} is outside its range "
                          f"[{self.min:g}, {self.max:g}]", kind, self.name)

    @property
    def is_real(self) -> bool:
        return self.kind is float


def range_check(variables: tuple[Var, ...]) -> Callable[[Any], None]:
    """A check of the numeric ``variables`` as attributes of an object, compiled to one
    expression (every step checks its inputs so); a failure is Refused by ``Var.check``."""
    tests = [f"{max(v.min, -sys.float_info.max)!r} <= obj.{v.name} <= "
             f"{min(v.max, sys.float_info.max)!r}" for v in variables]

    def name_the_failure(obj: Any) -> None:
        for var in variables:
            var.check(getattr(obj, var.name))
    namespace: dict[str, Any] = {"name_the_failure": name_the_failure}
    exec(f"def check(obj):\n    if not ({' and '.join(tests) or 'True'}):\n"
         "        name_the_failure(obj)\n", namespace)
    return namespace["check"]


def describe(root: Element, variables: tuple[Var, ...], typed: list[Element | None],
             reference: dict[str, int]) -> tuple[Element, list[tuple[str, tuple]]]:
    """Add to ``root`` what pythonfmu leaves out: exact starts, units and ranges on the
    ``typed`` elements, and <UnitDefinitions>. The emptied <ModelStructure>, and each output's
    ``reference`` with those it depends on while stepping and at initialisation."""
    for element, var in zip(typed, variables):
        if var.kind is str:
            continue
        if var.start is not None:
            element.set("start", repr(float(var.start)) if var.is_real else str(int(var.start)))
        if var.is_real:
            element.set("unit", var.unit)
            if var.unit in DISPLAY_UNIT:
                element.set("displayUnit", DISPLAY_UNIT[var.unit])
        for bound in ("min", "max"):
            if math.isfinite(getattr(var, bound)):
                element.set(bound, repr(var.kind(getattr(var, bound))))
    definitions = Element("UnitDefinitions")
    for name in sorted({v.unit for v in variables if v.is_real}):
        exponents, factor, display = UNITS[name]
        unit = SubElement(definitions, "Unit", name=name)
        base = {k: str(v) for k, v in exponents.items()}
        SubElement(unit, "BaseUnit", base | ({"factor": repr(factor)} if factor != 1.0 else {}))
        for display_name, display_factor in display.items():
            SubElement(unit, "DisplayUnit", name=display_name, factor=repr(display_factor))
    root.insert(list(root).index(root.find("CoSimulation")) + 1, definitions)
    structure = root.find("ModelStructure")
    structure.clear()
    inputs = {v.name for v in variables if v.causality == "input"}

    def ordered(names: Iterable[str]) -> list[str]:
        return [str(r) for r in sorted(reference[n] for n in names)]
    return structure, [(str(reference[v.name]), (ordered(d for d in v.depends if d in inputs),
                                                 ordered(v.depends + v.initial_depends)))
                       for v in variables if v.causality == "output"]
