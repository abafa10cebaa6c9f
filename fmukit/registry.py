"""The slave's variables registered with pythonfmu and indexed by value reference.

Parameters and inputs live as attributes of the slave, starting at their start
values; outputs are read through ``evaluate(get, undefined)``, which the slave
supplies (it builds the model when needed and turns what cannot be evaluated
into NaN, or 0 for an Integer).
"""
from __future__ import annotations

import math
from typing import Any, Callable

from .pythonfmu07 import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real
from .pythonfmu07 import String

from .variables import Var

_PYTHONFMU_TYPE = {float: Real, int: Integer, str: String}
Evaluate = Callable[[Callable[[Any], Any], Any], Any]


class Registry:
    """Every variable of a slave, by value reference, with its pythonfmu getter."""

    def __init__(self, slave: Fmi2Slave, variables: tuple[Var, ...], evaluate: Evaluate):
        self.by_vr: dict[int, Var] = {}
        self.real_getters: dict[int, Callable[[], float]] = {}
        self.integer_getters: dict[int, Callable[[], int]] = {}
        self.real_inputs: dict[int, str] = {}       # Real inputs: value reference -> name
        self.model_attributes: dict[int, str] = {}  # Real outputs that are model attributes
        for var in variables:
            self._register(slave, var, evaluate)

    def _register(self, slave: Fmi2Slave, var: Var, evaluate: Evaluate) -> None:
        kind = _PYTHONFMU_TYPE[var.kind]
        if var.causality == "output":
            get = var.get or (lambda s, name=var.name: getattr(s._model, name))

            def getter(get=get, undefined=math.nan if var.is_real else 0) -> Any:
                return evaluate(get, undefined)
            sv = kind(var.name, causality=Fmi2Causality.output,
                      variability=(Fmi2Variability.continuous if var.is_real
                                   else Fmi2Variability.discrete),
                      initial=Fmi2Initial.calculated, description=var.description,
                      getter=getter)
        else:
            setattr(slave, var.name, var.start)
            variability = (Fmi2Variability.fixed if var.causality == "parameter"
                           else Fmi2Variability.continuous)
            sv = kind(var.name, causality=Fmi2Causality[var.causality],
                      variability=variability, description=var.description)
        slave.register_variable(sv)
        vr = sv.value_reference
        self.by_vr[vr] = var
        if var.is_real:
            self.real_getters[vr] = sv.getter
            if var.causality == "input":
                self.real_inputs[vr] = var.name
            elif var.causality == "output" and var.get is None:
                self.model_attributes[vr] = var.name
        elif var.kind is int:
            self.integer_getters[vr] = sv.getter

    def var(self, vr: int) -> Var:
        """The variable with value reference ``vr``; ValueError if there is none."""
        var = self.by_vr.get(vr)
        if var is None:
            raise ValueError(f"no variable has value reference {vr}")
        return var
