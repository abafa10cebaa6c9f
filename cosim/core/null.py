"""The master's null backend: the FMUs' interfaces without their behaviour, to measure the master.

A ``NullInstance`` has the variables and feedthrough of the FMU at ``path`` (its model
description; the FMU is not loaded): outputs read 0.0, inputs and parameters are ignored, a
step returns at once. ``cosim.bench overhead`` reports a run on it as the master's own cost.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Iterable

from .fmi import feedthrough, read_description
from .instance import Instance


def _nothing(*args: Any, **kwargs: Any) -> None:
    return None


class NullInstance(Instance):
    """The interface of the FMU at ``path``; no behaviour."""

    call = _nothing
    enter_initialization = reset = free = _nothing

    def __init__(self, path: str | Path, name: str):
        description = read_description(self.path, name)
        self.guid = description.guid
        self.variables = {v.name: v for v in description.modelVariables}
        self.feedthrough = feedthrough(description)

    def fmi(self, name: str) -> Callable:
        return _nothing

    def get(self, names: Iterable[str]) -> dict[str, Any]:
        """The start values of the model description: a null instance holds nothing else."""
        return {name: self.variable(name).start for name in names}

    def reader(self, vrs: list[int]) -> Callable[[], list[float]]:
        values = [0.0] * len(vrs)
        return lambda: values

    def integer_reader(self, vrs: list[int]) -> Callable[[], list[int]]:
        values = [0] * len(vrs)
        return lambda: values

    def writer(self, vrs: list[int]) -> Callable[[list[float]], None]:
        return _nothing

    def stepper(self) -> Callable[[float, float], None]:
        return _nothing
