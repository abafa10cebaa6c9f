"""Fast getReal, setReal and getInteger: the work of a call decided once per list of references.

A master asks for the same value references at every step. The first call with a
list works out how to serve it (which getters, whether every reference is a
model attribute that one ``operator.attrgetter`` call can read, whether every
reference is a Real input that can be set as an attribute) and caches that; the
next calls only execute it. A list that is not of that kind gets ``None`` and the
slave lets pythonfmu serve it (and name any problem).
"""
from __future__ import annotations

import operator
from typing import Any, Callable

from .registry import Registry


class FastPaths:
    """Cached plans for the value-reference lists of one slave."""

    def __init__(self, slave: Any, registry: Registry):
        self._slave, self._registry = slave, registry
        self._reads: dict[tuple[int, ...], Callable[[], list[float]] | None] = {}
        self._writes: dict[tuple[int, ...], tuple[str, ...]] = {}

    def real_reader(self, vrs: list[int]) -> Callable[[], list[float]] | None:
        """The fastest correct way to read these Reals, or None if one is not a Real."""
        key = tuple(vrs)
        try:
            return self._reads[key]
        except KeyError:
            read = self._reads[key] = self._compile_read(key)
            return read

    def _compile_read(self, vrs: tuple[int, ...]) -> Callable[[], list[float]] | None:
        getters = self._registry.real_getters
        if not all(vr in getters for vr in vrs):
            return None
        each_getter = [getters[vr] for vr in vrs]

        def each() -> list[float]:
            return [float(get()) for get in each_getter]
        attributes_of = self._registry.model_attributes
        if not all(vr in attributes_of for vr in vrs):
            return each
        attributes = operator.attrgetter(*(attributes_of[vr] for vr in vrs))
        slave = self._slave

        def model_attributes() -> list[float]:     # the ship's states: one C-level call
            model = slave._model
            if model is None:
                return each()
            values = attributes(model)
            return list(values) if len(vrs) > 1 else [values]
        return model_attributes

    def input_names(self, vrs: list[int]) -> tuple[str, ...]:
        """The names of these Real inputs, or () if one is not a Real input."""
        key = tuple(vrs)
        names = self._writes.get(key)
        if names is None:
            inputs = self._registry.real_inputs
            names = self._writes[key] = (tuple(inputs[vr] for vr in vrs)
                                         if all(vr in inputs for vr in vrs) else ())
        return names

    def integers(self, vrs: list[int]) -> list[int] | None:
        """The current values of these Integers, or None if one is not an Integer."""
        getters = self._registry.integer_getters
        if all(vr in getters for vr in vrs):
            return [int(getters[vr]()) for vr in vrs]
        return None
