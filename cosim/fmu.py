"""One FMU instance driven through fmpy: variables by name, captured log, clear errors."""
from __future__ import annotations

import shutil
from collections import deque
from pathlib import Path
from typing import Any, Iterable

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
from fmpy.fmi1 import calloc, free

STATUS = ("ok", "warning", "discard", "error", "fatal", "pending")
BUILD_HINT = "build the FMUs with: python -m fmukit.build"
_CONVERT = {"Real": float, "Integer": int, "Boolean": bool, "String": str}


class FmuCallError(RuntimeError):
    """An FMI call returned discard, error or fatal; carries the FMU's own log."""

    def __init__(self, instance: str, call: str, time: float | None, status: str,
                 messages: Iterable[str]):
        self.instance, self.call, self.time, self.status = instance, call, time, status
        self.messages = list(messages)
        at = "" if time is None else f" at t = {time:.6g} s"
        log = "".join(f"\n  {instance} log: {m}" for m in self.messages)
        super().__init__(f"FMU '{instance}': {call}{at} returned {status}{log}")


class FmuInstance:
    """An instantiated co-simulation FMU.

    Raises FileNotFoundError or ValueError, naming the file and how to build it,
    when the FMU is missing or not a readable FMU.
    """

    def __init__(self, path: str | Path, name: str, unzip_dir: str | Path | None = None):
        self.path, self.name = Path(path), name
        if not self.path.is_file():
            raise FileNotFoundError(f"FMU for '{name}' not found: {self.path}; {BUILD_HINT}")
        try:
            self.description = read_model_description(str(self.path))
        except Exception as error:
            raise ValueError(f"{self.path} is not a readable FMU ({error}); {BUILD_HINT}") \
                from error
        self._owns_unzip_dir = unzip_dir is None
        self.unzip_dir = str(unzip_dir) if unzip_dir else extract(str(self.path))
        self.variables = {v.name: v for v in self.description.modelVariables}
        self.feedthrough = {o.variable.name: frozenset(d.name for d in o.dependencies)
                            if o.dependencies is not None else frozenset(
                                v.name for v in self.description.modelVariables
                                if v.causality == "input")
                            for o in self.description.outputs}
        self.log: deque[str] = deque(maxlen=50)
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(self._on_log)
        self._callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self._callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.slave = FMU2Slave(guid=self.description.guid, unzipDirectory=self.unzip_dir,
                               modelIdentifier=self.description.coSimulation.modelIdentifier,
                               instanceName=name)
        self.call("instantiate", self.slave.instantiate, callbacks=self._callbacks,
                  loggingOn=True)

    def _on_log(self, env, instance, status, category, message) -> None:
        self.log.append(f"[{STATUS[status] if status < len(STATUS) else status}] "
                        f"{message.decode('utf-8', 'replace')}")

    def call(self, what: str, function, *args, time: float | None = None, **kwargs) -> Any:
        """Call an fmpy function; turn a failed status into FmuCallError."""
        before = len(self.log)
        try:
            return function(*args, **kwargs)
        except FMICallException as error:
            status = str(error).rsplit("(", 1)[-1].rstrip(").")
            fresh = list(self.log)[before:] if len(self.log) > before else list(self.log)[-3:]
            raise FmuCallError(self.name, what, time, status, fresh) from error

    def variable(self, name: str):
        """The model variable, or ValueError listing the valid names."""
        try:
            return self.variables[name]
        except KeyError:
            raise ValueError(f"FMU '{self.name}' ({self.path.name}) has no variable '{name}'; "
                             f"it has: {', '.join(self.variables)}") from None

    def vr(self, name: str) -> int:
        return self.variable(name).valueReference

    def set(self, values: dict[str, Any], time: float | None = None) -> None:
        """Set variables by name, each with the FMI type of its declaration."""
        for name, value in values.items():
            kind = self.variable(name).type
            try:
                converted = _CONVERT[kind](value)
            except (TypeError, ValueError):
                raise ValueError(f"FMU '{self.name}': {name} needs a {kind} value, "
                                 f"got {value!r}") from None
            setter = getattr(self.slave, f"set{kind}")
            self.call(f"set {name} = {value!r}", setter, [self.vr(name)], [converted],
                      time=time)

    def get(self, names: Iterable[str]) -> dict[str, Any]:
        """Current values of variables by name."""
        out = {}
        for name in names:
            getter = getattr(self.slave, f"get{self.variable(name).type}")
            value = self.call(f"get {name}", getter, [self.vr(name)])[0]
            out[name] = value.decode("utf-8") if isinstance(value, bytes) else value
        return out

    def initialize(self, parameters: dict[str, Any] | None = None,
                   start_time: float = 0.0) -> None:
        """setupExperiment, parameters, enter and exit initialisation mode."""
        self.enter_initialization(start_time)
        self.set(parameters or {}, time=start_time)
        self.exit_initialization(start_time)

    def enter_initialization(self, start_time: float = 0.0) -> None:
        self.call("setupExperiment", self.slave.setupExperiment, startTime=start_time)
        self.call("enterInitializationMode", self.slave.enterInitializationMode)

    def exit_initialization(self, start_time: float = 0.0) -> None:
        self.call("exitInitializationMode", self.slave.exitInitializationMode,
                  time=start_time)

    def do_step(self, t: float, h: float) -> None:
        self.call("doStep", self.slave.doStep, t, h, time=t)

    # Batched calls by value reference, for the master's loop.
    def get_real(self, vrs: list[int]) -> list[float]:
        return self.call("getReal", self.slave.getReal, vrs)

    def get_integer(self, vrs: list[int]) -> list[int]:
        return self.call("getInteger", self.slave.getInteger, vrs)

    def set_real(self, vrs: list[int], values: list[float]) -> None:
        self.call("setReal", self.slave.setReal, vrs, values)

    def free(self) -> None:
        """Terminate, free the instance and remove the extracted files."""
        try:
            self.slave.terminate()
        except FMICallException:
            pass
        self.slave.freeInstance()
        if self._owns_unzip_dir:
            shutil.rmtree(self.unzip_dir, ignore_errors=True)
