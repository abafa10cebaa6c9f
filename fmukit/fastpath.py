"""Plans for reading Reals and Integers and setting Real inputs, made once per list of value
references (a master asks for the same lists at every step).

A plan gives what the FMI call gives in every state of the slave (NaN once it has failed),
so a host in the same process may call it itself; a list the plans do not serve gets
``None``, and pythonfmu serves it. Model attributes are read with one
``operator.attrgetter``; other values each through their reader within one ``try``, and
again one by one where that fails.
"""
from __future__ import annotations

import operator
from typing import Any, Callable

from .registry import Registry
from .variables import Var

Reader = Callable[[], list[float]]
Writer = Callable[[list[float]], None]


class FastPaths:
    """Cached plans for the value-reference lists of one slave."""

    def __init__(self, slave: Any, registry: Registry):
        self._slave, self._registry = slave, registry
        self._reads: dict[tuple[int, ...], Reader | None] = {}
        self._writes: dict[tuple[int, ...], Writer | None] = {}
        self._integer_reads: dict[tuple[int, ...], Callable[[], list[int]] | None] = {}

    @staticmethod
    def _planned(plans: dict, vrs: list[int], compile_plan: Callable) -> Any:
        """The plan for ``vrs`` from ``plans``, compiled the first time."""
        key = tuple(vrs)
        try:
            return plans[key]
        except KeyError:
            plan = plans[key] = compile_plan(key)
            return plan

    def real_reader(self, vrs: list[int]) -> Reader | None:
        """The plan reading these Reals, or None if one is not a Real."""
        return self._planned(self._reads, vrs, self._compile_read)

    def _compile_read(self, vrs: tuple[int, ...]) -> Reader | None:
        getters = self._registry.real_getters
        if not all(vr in getters for vr in vrs):
            return None
        attributes_of = self._registry.model_attributes
        if not all(vr in attributes_of for vr in vrs):
            return self._evaluated(vrs, getters, float)
        slave, each = self._slave, self._each(vrs, getters, float)
        attributes = operator.attrgetter(*(attributes_of[vr] for vr in vrs))
        single = len(vrs) == 1

        def model_attributes() -> list[float]:   # one C-level call
            model = slave._model
            if model is None or slave.failure:
                return each()
            values = attributes(model)
            return [values] if single else list(values)
        return model_attributes

    def integer_reader(self, vrs: list[int]) -> Callable[[], list[int]] | None:
        """The plan reading these Integers, or None if one is not an Integer."""
        return self._planned(self._integer_reads, vrs, self._compile_integer_read)

    def _compile_integer_read(self, vrs: tuple[int, ...]) -> Callable[[], list[int]] | None:
        getters = self._registry.integer_getters
        return self._evaluated(vrs, getters, int) if all(vr in getters for vr in vrs) else None

    @staticmethod
    def _each(vrs: tuple[int, ...], getters: dict[int, Callable[[], Any]],
              convert: type) -> Callable[[], list]:
        """Each value through its own getter: NaN (0) for each one that cannot be read."""
        each_getter = [getters[vr] for vr in vrs]
        return lambda: [convert(get()) for get in each_getter]

    def _evaluated(self, vrs: tuple[int, ...], getters: dict[int, Callable[[], Any]],
                   convert: type) -> Callable[[], list]:
        slave, each = self._slave, self._each(vrs, getters, convert)
        gets = [self._get(self._registry.by_vr[vr]) for vr in vrs]
        first = gets[0] if len(gets) == 1 else None     # a feedthrough output, typically

        def evaluated() -> list:
            if slave._model is None or slave.failure:
                return each()
            try:
                return ([convert(first(slave))] if first
                        else [convert(get(slave)) for get in gets])
            except (ValueError, ArithmeticError):
                return each()
        return evaluated

    @staticmethod
    def _get(var: Var) -> Callable[[Any], Any]:
        """How a Real's value is read from the slave."""
        if var.causality != "output":
            return operator.attrgetter(var.name)
        return var.get or operator.attrgetter(f"_model.{var.name}")

    def input_writer(self, vrs: list[int]) -> Writer | None:
        """The plan setting these Real inputs, or None if one is not a Real input."""
        return self._planned(self._writes, vrs, self._compile_write)

    def _compile_write(self, vrs: tuple[int, ...]) -> Writer | None:
        inputs = self._registry.real_inputs
        if not all(vr in inputs for vr in vrs):
            return None
        slave, names = self._slave, tuple(inputs[vr] for vr in vrs)
        sequence, attributes = slave.sequence, vars(slave)
        if any(hasattr(type(slave), name) for name in names):   # a property: set it
            def assign(values: list[float]) -> None:
                for name, value in zip(names, values):
                    setattr(slave, name, float(value))
        else:                                                    # plain attributes
            def assign(values: list[float]) -> None:
                attributes.update(zip(names, map(float, values)))

        def write(values: list[float]) -> None:
            if sequence.phase == "terminated":
                slave._set(list(vrs), values, float)     # refused, naming the input
            assign(values)
        return write
