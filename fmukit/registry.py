"""The slave's variables registered with pythonfmu (through the adapter's ``fmi_variable``)
and indexed by value reference. Parameters and inputs are attributes of the slave; outputs
are read through the slave's ``evaluate(get, undefined)``.
"""
from __future__ import annotations

import math
from typing import Any, Callable

from .variables import Var


class Registry:
    """Every variable of a slave by value reference (pythonfmu's ``vars`` hold the getters)."""

    def __init__(self, slave: Any, variables: tuple[Var, ...],
                 evaluate: Callable[[Callable[[Any], Any], Any], Any]):
        self.by_vr: dict[int, Var] = {}
        for var in variables:
            getter = None
            if var.causality == "output":
                get = var.get or (lambda s, name=var.name: getattr(s._model, name))

                def getter(get=get, undefined=math.nan if var.is_real else 0) -> Any:
                    return evaluate(get, undefined)
            else:
                setattr(slave, var.name, var.start)
            sv = slave.fmi_variable(var, getter)
            slave.register_variable(sv)
            self.by_vr[sv.value_reference] = var

    def var(self, vr: int) -> Var:
        """The variable with value reference ``vr``; ValueError if there is none."""
        var = self.by_vr.get(vr)
        if var is None:
            raise ValueError(f"no variable has value reference {vr}")
        return var


def pythonfmu_variable(var: Var, getter: Callable[[], Any] | None, kind: type,
                       causality: Any, variability: Any, initial: Any, **extra: Any) -> Any:
    """The pythonfmu(3) variable of ``kind`` for ``var``, given that version's enums."""
    if var.causality == "output":
        return kind(var.name, causality=causality.output, variability=(
            variability.continuous if var.is_real else variability.discrete),
            initial=initial.calculated, description=var.description, getter=getter, **extra)
    return kind(var.name, causality=causality[var.causality], variability=(
        variability.fixed if var.causality == "parameter" else variability.continuous),
        description=var.description, **extra)
