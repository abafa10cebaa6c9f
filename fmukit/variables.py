"""``Var``: an FMU variable declared once, the source of its pythonfmu registration, its
modelDescription.xml entry (the same in FMI 2.0 and 3.0; each adapter's ``to_xml`` puts it
where its version wants it) and the range check its values must pass.
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Any, Callable, Iterable
from xml.etree.ElementTree import Element

from .refusals import Refused
from .units import DISPLAY_UNIT, UNITS, unit_definitions


@dataclass(frozen=True)
class Var:
    """One FMU variable, declared once. Build it with the class methods."""

    name: str
    causality: str                    # "parameter" | "input" | "output"
    unit: str = "1"                   # key of fmukit.units.UNITS (Real only)
    description: str = ""
    start: float | int | str | None = None
    kind: type = float                # float (Real), int (Integer) or str (String)
    depends: tuple[str, ...] = ()     # outputs: inputs and parameters they depend on
    initial_depends: tuple[str, ...] = ()     # outputs: further knowns, at initialisation only
    get: Callable[[Any], Any] | None = None   # outputs: value from the slave
    min: float = -math.inf            # inputs and parameters: the valid range, written to
    max: float = math.inf             # modelDescription.xml and enforced (NaN is never valid)

    def __post_init__(self) -> None:
        if self.kind is float and self.unit not in UNITS:
            raise ValueError(f"variable {self.name}: unit {self.unit!r} is not one of "
                             f"{', '.join(UNITS)} (fmukit/units.py)")

    @classmethod
    def parameter(cls, name: str, start: float | int | str, unit: str = "1",
                  description: str = "", min: float = -math.inf,
                  max: float = math.inf) -> Var:
        """A fixed parameter; its Python type (float, int, str) sets the FMI type."""
        return cls(name, "parameter", unit, description, start, type(start), min=min, max=max)

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

    def type_attributes(self) -> dict[str, str]:
        """The attributes of a numeric variable's type, in the order they are written."""
        attributes = {}
        if self.is_real:
            if self.start is not None:
                attributes["start"] = repr(float(self.start))    # shortest exact form
            attributes["unit"] = self.unit
            if self.unit in DISPLAY_UNIT:
                attributes["displayUnit"] = DISPLAY_UNIT[self.unit]
        elif self.start is not None:
            attributes["start"] = str(int(self.start))
        for bound in ("min", "max"):
            value = getattr(self, bound)
            if math.isfinite(value):
                attributes[bound] = repr(self.kind(value))
        return attributes


def range_check(variables: tuple[Var, ...]) -> Callable[[Any], None]:
    """A check of the numeric ``variables`` as attributes of an object, compiled to one
    expression (ranges clipped to the finite doubles, which no NaN passes); a failure is
    Refused by ``Var.check``. Every step checks its inputs so."""
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
    """Add each numeric variable's attributes to its ``typed`` element and <UnitDefinitions>
    to the model description ``root``. The emptied <ModelStructure>, and for each output its
    ``reference`` and those it depends on while stepping (its inputs: direct feedthrough)
    and at initialisation (inputs and parameters, and its further knowns then), ordered."""
    for element, var in zip(typed, variables):
        if var.kind is not str:
            element.attrib.update(var.type_attributes())
    root.insert(list(root).index(root.find("CoSimulation")) + 1,
                unit_definitions({v.unit for v in variables if v.is_real}))
    structure = root.find("ModelStructure")
    structure.clear()
    inputs = {v.name for v in variables if v.causality == "input"}

    def ordered(names: Iterable[str]) -> list[str]:
        return [str(r) for r in sorted(reference[n] for n in names)]
    return structure, [(str(reference[v.name]), (ordered(d for d in v.depends if d in inputs),
                                                 ordered(v.depends + v.initial_depends)))
                       for v in variables if v.causality == "output"]
