"""The master's FMI backend: one FMU instance driven through fmpy, its log captured, clear errors.

``FmuInstance(path, name)`` is an FMI 2.0 instance (``Fmu2Instance``, here) or an FMI 3.0
one (``cosim.core.fmi3.Fmu3Instance``), by the fmiVersion of the FMU's model description.
The master speaks FMI 2.0's type names: ``read_description`` gives an FMI 3.0 FMU's
Float64 and Int32 variables as Real and Integer (``FMI3_TYPES``), and each instance maps
the master's call names ("setReal", "getInteger", ...) to its version's. Components are
wired by variable name; each instance keeps its own value references (an FMI 3.0 twin
of ours numbers its variables one higher than its FMI 2.0 twin: ``time`` is its 0).
"""
from __future__ import annotations

import shutil
from collections import deque
from pathlib import Path
from typing import Any, Callable

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException, calloc, free
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2Integer, fmi2Real,
                       fmi2True, fmi2ValueReference)
from fmpy.model_description import ModelDescription

from fmubuild.project import FMUS
from .errors import FmuNotFound, FmuUnreadable
from .instance import FmuCallError, Instance, LogRecord, logged_error, one_account

STATUS = ("ok", "warning", "discard", "error", "fatal", "pending")
VERSIONS = (2, 3)
"""The FMI versions the master runs."""
FMI3_TYPES = {"Float64": "Real", "Int32": "Integer"}
"""FMI 3.0 type names as the master's (FMI 2.0's); Boolean and String are the same in both."""


def fmi_version(description: ModelDescription) -> int:
    """The major FMI version of a model description: 2 or 3; ValueError for another."""
    version = int(description.fmiVersion.partition(".")[0])
    if version not in VERSIONS:
        raise ValueError(f"an FMI {description.fmiVersion} FMU; the master runs FMI 2.0 and "
                         "3.0 co-simulation FMUs")
    return version


def read_description(path: Path, name: str) -> ModelDescription:
    """An FMU's model description, FMI 3.0 type names as FMI 2.0's (``FMI3_TYPES``);
    FmuNotFound or FmuUnreadable naming the file (and whether it is named as one of this
    project's FMUs) when it is missing or not readable, ValueError when it is not a
    co-simulation FMU of FMI 2.0 or 3.0."""
    ours = path.stem in FMUS
    if not path.is_file():
        raise FmuNotFound(f"FMU for '{name}' not found: {path}", ours)
    try:
        description = read_model_description(str(path))
    except Exception as error:
        raise FmuUnreadable(f"{path} is not a readable FMU ({error})", ours) from error
    try:
        version = fmi_version(description)
    except ValueError as error:
        raise ValueError(f"{path} is {error}") from None
    if description.coSimulation is None:
        raise ValueError(f"{path} is not a co-simulation FMU (model exchange only)")
    if version == 3:
        for variable in description.modelVariables:
            variable.type = FMI3_TYPES.get(variable.type, variable.type)
    return description


def feedthrough(description: ModelDescription) -> dict[str, frozenset[str]]:
    """Each output's inputs, from the model structure (all inputs where it declares none)."""
    inputs = frozenset(v.name for v in description.modelVariables if v.causality == "input")
    return {o.variable.name: (frozenset(d.name for d in o.dependencies)
                              if o.dependencies is not None else inputs)
            for o in description.outputs}


class FmuInstance(Instance):
    """An instantiated co-simulation FMU, FMI 2.0 or 3.0 (the class is chosen by the FMU's
    fmiVersion).

    Raises FmuNotFound, FmuUnreadable or ValueError, naming the file, when the FMU is
    missing or not a readable co-simulation FMU, and FmuCallError when it cannot be
    instantiated (its extracted files are removed).
    """

    slave: Any                         # fmpy's FMU2Slave or FMU3Slave

    def __new__(cls, path: str | Path, name: str, unzip_dir: str | Path | None = None):
        chosen = cls
        if cls is FmuInstance:
            from .fmi3 import Fmu3Instance     # here: fmi3 builds on this module
            version = fmi_version(read_description(Path(path), name))
            chosen = Fmu3Instance if version == 3 else Fmu2Instance
        return super().__new__(chosen)

    def __init__(self, path: str | Path, name: str, unzip_dir: str | Path | None = None):
        self.path, self.name = Path(path), name
        self.description = read_description(self.path, name)
        self._owns_unzip_dir = unzip_dir is None
        self.unzip_dir = str(unzip_dir) if unzip_dir else extract(str(self.path))
        self.variables = {v.name: v for v in self.description.modelVariables
                          if v.causality != "independent"}      # FMI 3.0's time
        self.feedthrough = feedthrough(self.description)
        self.log: deque[LogRecord] = deque(maxlen=50)     # the last messages
        self.logged = 0                              # how many there have been
        try:
            self._instantiate()
        except Exception as error:        # fmpy raises a plain Exception when it gets NULL
            self._remove_unzip_dir()
            if isinstance(error, FmuCallError):
                raise
            raise FmuCallError(name, f"instantiate ({self.path.name})", None, "failure",
                               [*self.log, LogRecord("fatal", None,
                                                     f"{type(error).__name__}: {error}")]
                               ) from error

    def _instantiate(self) -> None:
        """Load the FMU's library and instantiate it, logging into ``_log``."""
        raise NotImplementedError

    @property
    def guid(self) -> str:
        """The FMI 2.0 guid, or the FMI 3.0 instantiationToken."""
        return self.description.guid

    def _log(self, status: int, category: bytes | None, message: bytes) -> None:
        self.logged += 1
        self.log.append(LogRecord(STATUS[status] if status < len(STATUS) else str(status),
                                  category.decode("utf-8", "replace") if category else None,
                                  message.decode("utf-8", "replace")))

    def call(self, what: str, function: Callable, *args, time: float | None = None,
             strict: bool = False, **kwargs) -> Any:
        """Call an fmpy function; turn a failed status (or, ``strict``, an error logged) into
        FmuCallError."""
        before = self.logged
        try:
            result = function(*args, **kwargs)
        except FMICallException as error:
            raise FmuCallError(self.name, what, time, STATUS[error.status],
                               self._since(before)) from error
        if strict and logged_error(self._since(before)):
            raise FmuCallError(self.name, what, time, "OK but logged an error",
                               self._since(before))
        return result

    def _since(self, before: int) -> list[LogRecord]:
        """The log of the call that began when ``before`` had been logged (the last 50
        messages, as the log keeps no more), each failure told once."""
        new = self.logged - before
        return one_account(list(self.log)[-new:] if new else [])

    def reset(self) -> None:
        self.call("reset", self.slave.reset)

    # Prepared calls: the raw FMI functions of the FMU's library (fmpy's ``dll``, their
    # argument types set by fmpy) on preallocated ctypes arrays, without fmpy's per-call
    # wrapping, which costs more than the call itself.
    def _status(self, what: str, status: int, before: int, time: float | None = None) -> None:
        if status > 1:                      # discard, error, fatal
            raise FmuCallError(self.name, what, time, STATUS[status], self._since(before))

    def free(self) -> None:
        """Terminate, free the instance and remove the extracted files."""
        try:
            self.slave.terminate()
        except FMICallException:
            pass
        self.slave.freeInstance()
        self._remove_unzip_dir()

    def _remove_unzip_dir(self) -> None:
        if self._owns_unzip_dir:
            shutil.rmtree(self.unzip_dir, ignore_errors=True)


class Fmu2Instance(FmuInstance):
    """An FMI 2.0 co-simulation FMU through fmpy's FMU2Slave."""

    def _instantiate(self) -> None:
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(self._on_log)
        self._callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self._callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.slave = FMU2Slave(guid=self.description.guid, unzipDirectory=self.unzip_dir,
                               modelIdentifier=self.description.coSimulation.modelIdentifier,
                               instanceName=self.name)
        self.call("instantiate", self.slave.instantiate, callbacks=self._callbacks,
                  loggingOn=True)

    def _on_log(self, env, instance, status, category, message) -> None:
        self._log(status, category, message)

    def fmi(self, name: str):
        return getattr(self.slave, name)

    def enter_initialization(self, start_time: float = 0.0) -> None:
        self.call("setupExperiment", self.slave.setupExperiment, startTime=start_time)
        self.call("enterInitializationMode", self.slave.enterInitializationMode)

    def reader(self, vrs: list[int]):
        return self._getter("fmi2GetReal", fmi2Real, vrs)

    def integer_reader(self, vrs: list[int]):
        return self._getter("fmi2GetInteger", fmi2Integer, vrs)

    def _getter(self, function: str, ctype, vrs: list[int]):
        get, component = getattr(self.slave.dll, function), self.slave.component
        n = len(vrs)
        refs, values = (fmi2ValueReference * n)(*vrs), (ctype * n)()
        what = function.removeprefix("fmi2")

        def read() -> list:
            before = self.logged
            status = get(component, refs, n, values)
            if status:
                self._status(what, status, before)
            return values[:]
        return read

    def writer(self, vrs: list[int]):
        set_, component = self.slave.dll.fmi2SetReal, self.slave.component
        n = len(vrs)
        refs, values = (fmi2ValueReference * n)(*vrs), (fmi2Real * n)()

        def write(new: list[float]) -> None:
            values[:] = new
            before = self.logged
            status = set_(component, refs, n, values)
            if status:
                self._status("setReal", status, before)
        return write

    def stepper(self):
        do_step, component = self.slave.dll.fmi2DoStep, self.slave.component

        def step(t: float, h: float) -> None:
            before = self.logged
            status = do_step(component, t, h, fmi2True)
            if status:
                self._status("doStep", status, before, t)
        return step
