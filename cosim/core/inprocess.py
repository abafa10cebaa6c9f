"""The master's in-process backend: the FMUs' Python classes, called without FMI.

An ``InProcessInstance`` has the same interface as ``cosim.core.fmi.FmuInstance`` but
instantiates the slave class an FMU was built from (``fmukit.packaging.FMUS``) in this
process and calls its methods directly. A run on this backend differs from a
co-simulation only by the FMI layer (C wrapper, fmpy, ctypes), which is what the
equality tests compare.
"""
from __future__ import annotations

import importlib
import inspect
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fmukit.entry import explain, unnamed
from fmukit.packaging import FMUS
from fmukit.slave import ModelSlave

from .instance import FmuCallError, Instance, logged_error

_FMI_TYPE = {float: "Real", int: "Integer", str: "String"}


@dataclass(frozen=True)
class VariableInfo:
    name: str
    valueReference: int
    type: str
    causality: str
    unit: str


def slave_class(fmu_name: str) -> type[ModelSlave]:
    """The ModelSlave subclass that ``fmus/<fmu_name>.fmu`` is built from."""
    if fmu_name not in FMUS:
        raise ValueError(f"no FMU named '{fmu_name}' is built by this project "
                         f"(known: {', '.join(FMUS)})")
    module_name = FMUS[fmu_name][0].removesuffix(".py").replace("/", ".")
    module = importlib.import_module(module_name)
    return next(cls for _, cls in inspect.getmembers(module, inspect.isclass)
                if issubclass(cls, ModelSlave) and getattr(cls, "model_name", None) == fmu_name)


class InProcessInstance(Instance):
    """A slave class instantiated and driven in this process."""

    def __init__(self, path: str | Path, name: str):
        self.path, self.name = Path(path), name
        self.slave = slave_class(self.path.stem)(instance_name=name)
        self.variables = {}
        for vr, var in self.slave.registry.by_vr.items():
            self.variables[var.name] = VariableInfo(var.name, vr, _FMI_TYPE[var.kind],
                                                    var.causality,
                                                    var.unit if var.is_real else "")
        inputs = {v.name for v in self.slave.variables if v.causality == "input"}
        self.feedthrough = {v.name: frozenset(v.depends) & inputs
                            for v in self.slave.variables if v.causality == "output"}

    def call(self, what: str, function, *args, time: float | None = None,
             strict: bool = False) -> Any:
        """Call a slave method; an exception, a refused step or (``strict``) an error logged
        becomes FmuCallError."""
        try:
            result = function(*args)
        except Exception as error:
            raise FmuCallError(self.name, what, time, "fatal",
                               [*self._drain(), unnamed(self.name, explain(error))]) from error
        if result is False:
            raise FmuCallError(self.name, what, time, "discard", self._drain())
        messages = self._drain()
        if strict and logged_error(messages):
            raise FmuCallError(self.name, what, time, "OK but logged an error", messages)
        return result

    def _drain(self) -> list[str]:
        messages = [f"[{m.status.name}] {unnamed(self.name, m.msg)}"
                    for m in self.slave.log_queue]
        self.slave.log_queue.clear()
        return messages

    def fmi(self, name: str):
        """The slave method behind an FMI call name: setReal -> set_real."""
        return getattr(self.slave, re.sub(r"(?<!^)([A-Z])", r"_\1", name).lower())

    def enter_initialization(self, start_time: float = 0.0) -> None:
        self.call("setupExperiment", self.slave.setup_experiment, start_time)
        self.call("enterInitializationMode", self.slave.enter_initialization_mode)

    def reset(self) -> None:
        """A fresh slave object, as pythonfmu's fmi2Reset makes one."""
        self.slave = type(self.slave)(instance_name=self.name)

    def free(self) -> None:
        """Terminate, if the slave was initialised (as fmi2FreeInstance may follow any call)."""
        if self.slave.sequence.phase == "step":
            self.slave.terminate()
