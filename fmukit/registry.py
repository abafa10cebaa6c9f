"""A slave's variables by value reference, and plans reading or setting a list of them, made
once per list; a plan gives what the FMI call gives, so a host in this process may call it."""
from __future__ import annotations

import functools
import math
import operator
from typing import Any, Callable

from .variables import Var

Reader = Callable[[], list]
Writer = Callable[[list[float]], None]


class Registry:
    """Every variable of a slave by value reference (``by_vr``), and its cached plans."""

    def __init__(self, slave: Any, variables: tuple[Var, ...],
                 evaluate: Callable[[Callable[[Any], Any], Any], Any]):
        self._slave = slave
        self._plans: dict[tuple, Reader | Writer | None] = {}
        self.by_vr: dict[int, Var] = {}
        for var in variables:
            getter = None
            if var.causality == "output":
                get = var.get or (lambda s, name=var.name: getattr(s.model, name))
                getter = functools.partial(evaluate, get, math.nan if var.is_real else 0)
            else:
                setattr(slave, var.name, var.start)
            sv = slave.fmi_variable(var, getter)
            slave.register_variable(sv)
            self.by_vr[sv.value_reference] = var

    def _planned(self, kind: type | None, vrs: list[int]) -> Reader | Writer | None:
        key = (kind, *vrs)
        if key not in self._plans:
            self._plans[key] = (self._writer(key[1:]) if kind is None
                                else self._reader(key[1:], kind))
        return self._plans[key]

    # The plan reading these Reals (Integers), setting these Real inputs; None if one is not.
    real_reader = functools.partialmethod(_planned, float)
    integer_reader = functools.partialmethod(_planned, int)
    input_writer = functools.partialmethod(_planned, None)

    def _reader(self, vrs: tuple[int, ...], kind: type) -> Reader | None:
        slave, by_vr = self._slave, self.by_vr
        if not all(vr in by_vr and by_vr[vr].kind is kind for vr in vrs):
            return None
        declared = [by_vr[vr] for vr in vrs]
        getters = [slave.vars[vr].getter for vr in vrs]     # NaN (0) where one cannot read
        gets = [v.get or operator.attrgetter(f"_model.{v.name}" if v.causality == "output"
                                             else v.name) for v in declared]
        single = len(vrs) == 1                           # a feedthrough output, typically
        if kind is float and all(v.causality == "output" and not v.get for v in declared):
            attributes, gets = operator.attrgetter(*(v.name for v in declared)), None

        def read() -> list:
            model = slave._model
            if model is not None and not slave.failure:
                try:
                    if gets is None:
                        values = attributes(model)            # one C-level call
                        return [values] if single else list(values)
                    return [kind(get(slave)) for get in gets]
                except (ValueError, ArithmeticError):
                    pass
            return [kind(get()) for get in getters]
        return read

    def _writer(self, vrs: tuple[int, ...]) -> Writer | None:
        slave, by_vr = self._slave, self.by_vr
        if not all(vr in by_vr and by_vr[vr].is_real and by_vr[vr].causality == "input"
                   for vr in vrs):
            return None
        names, sequence = tuple(by_vr[vr].name for vr in vrs), slave.sequence

        def write(values: list[float]) -> None:
            if sequence.phase == "terminated":
                slave._set(list(vrs), values, float)     # refused, naming the input
            for name, value in zip(names, values):
                setattr(slave, name, float(value))
        return write


def pythonfmu_variable(var: Var, getter: Callable[[], Any] | None, kind: type,
                       causality: Any, variability: Any, initial: Any, **extra: Any) -> Any:
    """The pythonfmu(3) variable of ``kind`` for ``var``, given that version's enums."""
    if var.causality == "output":
        return kind(var.name, causality=causality.output, variability=(
            variability.continuous if var.is_real else variability.discrete),
            initial=initial.calculated, description=var.description, getter=getter, **extra)
    return kind(var.name, causality=causality[var.causality], variability=(
        variability.continuous if var.causality == "input" else
        variability.tunable if var.tunable else variability.fixed),
        description=var.description, **extra)
