"""The master's null backend: components that cost nothing, to measure the master itself.

A ``NullInstance`` has the variables and the feedthrough of the FMU at ``path``
(read from its model description, without loading it) and does nothing: its
outputs read 0.0, its inputs and parameters are ignored, a step returns at once.
A master on this backend pays only for its own work (coupling, bookkeeping,
recording), which is what ``cosim.bench`` reports as the master's cost. Its
results mean nothing.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Iterable

from .fmi import feedthrough, read_description
from .instance import Instance


class NullInstance(Instance):
    """The interface of the FMU at ``path``; no behaviour."""

    def __init__(self, path: str | Path, name: str):
        self.path, self.name = Path(path), name
        description = read_description(self.path, name)
        self.guid = description.guid
        self.variables = {v.name: v for v in description.modelVariables}
        self.feedthrough = feedthrough(description)

    def call(self, what: str, function: Callable, *args, time: float | None = None,
             strict: bool = False) -> Any:
        return None

    def fmi(self, name: str) -> Callable:
        return lambda *args: None

    def enter_initialization(self, start_time: float = 0.0) -> None:
        pass

    def reset(self) -> None:
        pass

    def free(self) -> None:
        pass

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
        return lambda values: None

    def stepper(self) -> Callable[[float, float], None]:
        return lambda t, h: None
