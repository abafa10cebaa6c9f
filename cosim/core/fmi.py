"""The master's FMI backend: an FMU of FMI 2.0 or 3.0 driven through fmpy, its log kept.
The master speaks FMI 2.0's names; FMI 3.0's types and calls are mapped to them."""
from __future__ import annotations

import contextlib
import functools
import shutil
from collections import deque
from ctypes import byref
from pathlib import Path
from typing import Any, Callable

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException, calloc, free
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2Integer, fmi2Real,
                       fmi2ValueReference)
from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64, fmi3Int32, fmi3ValueReference
from fmpy.model_description import ModelDescription

from .archives import unpack
from .system import FmuNotFound, FmuUnreadable
from .instance import FmuCallError, Instance, LogRecord, logged_error

STATUS = ("ok", "warning", "discard", "error", "fatal", "pending")
VERSIONS = (2, 3)
FMI3_TYPES = {"Float64": "Real", "Int32": "Integer"}     # Boolean and String: the same
CALLS = {"setReal": "setFloat64", "getReal": "getFloat64",
         "setInteger": "setInt32", "getInteger": "getInt32",
         "getFMUstate": "getFMUState", "setFMUstate": "setFMUState",
         "freeFMUstate": "freeFMUState", "serializeFMUstate": "serializeFMUState",
         "deSerializeFMUstate": "deserializeFMUState"}          # FMI 2.0's: FMI 3.0's
RAW_TYPES = {2: (fmi2ValueReference, {"Real": ("Real", fmi2Real),
                                     "Integer": ("Integer", fmi2Integer)}),
             3: (fmi3ValueReference, {"Real": ("Float64", fmi3Float64),
                                     "Integer": ("Int32", fmi3Int32)})}


def fmi_version(description: ModelDescription) -> int:
    """2 or 3, the major FMI version of a model description."""
    return int(description.fmiVersion.partition(".")[0])


def read_description(path: str | Path, name: str = "", ours: bool = False) -> ModelDescription:
    """An FMU's model description, FMI 3.0 type names as FMI 2.0's, cached by file version
    (read-only); FmuNotFound, FmuUnreadable or ValueError naming the file."""
    path = Path(path)
    if not path.is_file():
        raise FmuNotFound(f"FMU for '{name}' not found: {path}", ours)
    stat = path.stat()
    return _description(path.resolve(), stat.st_size, stat.st_mtime_ns, ours)


@functools.lru_cache(maxsize=256)
def _description(path: Path, size: int, mtime_ns: int, ours: bool) -> ModelDescription:
    try:
        description = read_model_description(str(path))
    except Exception as error:
        raise FmuUnreadable(f"{path} is not a readable FMU ({error})", ours) from error
    if fmi_version(description) not in VERSIONS:
        raise ValueError(f"{path} is an FMI {description.fmiVersion} FMU; the master runs FMI "
                         "2.0 and 3.0 co-simulation FMUs")
    if description.coSimulation is None:
        raise ValueError(f"{path} is not a co-simulation FMU (model exchange only)")
    if fmi_version(description) == 3:
        for variable in description.modelVariables:
            variable.type = FMI3_TYPES.get(variable.type, variable.type)
    return description


def described(description: ModelDescription) -> tuple[dict[str, Any], dict[str, frozenset]]:
    """(the variables by name but FMI 3.0's time, each output's inputs from the model
    structure: all inputs where it declares none)."""
    inputs = frozenset(v.name for v in description.modelVariables if v.causality == "input")
    return ({v.name: v for v in description.modelVariables if v.causality != "independent"},
            {o.variable.name: (frozenset(d.name for d in o.dependencies)
                               if o.dependencies is not None else inputs)
             for o in description.outputs})


class FmuInstance(Instance):
    """A co-simulation FMU through fmpy; an FMI 3.0 step asking to end the simulation fails."""

    def __init__(self, path: str | Path, name: str, unzip_dir: str | Path | None = None):
        """``unzip_dir``: the FMU extracted there already, kept (tests/fmu_fuzz.py's)."""
        self.description = read_description(self.path, name)
        self.fmi_version, self.guid = fmi_version(self.description), self.description.guid
        self._owns_unzip_dir = unzip_dir is None
        self.unzip_dir = str(unzip_dir) if unzip_dir else str(unpack(self.path))
        self.variables, self.feedthrough = described(self.description)
        self.log: deque[LogRecord] = deque(maxlen=50)     # the last messages
        self.logged = 0                              # how many there have been

        def log(*args) -> None:      # FMI 2.0's logger, FMI 3.0's logMessage: the last three
            status, category, message = args[-3:]                   # of their arguments
            self.logged += 1
            self.log.append(LogRecord(STATUS[status] if status < len(STATUS) else str(status),
                                      category.decode("utf-8", "replace") if category else None,
                                      message.decode("utf-8", "replace")))
        try:                  # fmpy raises a plain Exception when it gets NULL
            self.slave = (FMU2Slave if self.fmi_version == 2 else FMU3Slave)(
                guid=self.guid, unzipDirectory=self.unzip_dir, instanceName=name,
                modelIdentifier=self.description.coSimulation.modelIdentifier)
            if self.fmi_version == 2:
                self._callbacks = fmi2CallbackFunctions(
                    logger=fmi2CallbackLoggerTYPE(log),
                    allocateMemory=fmi2CallbackAllocateMemoryTYPE(calloc),
                    freeMemory=fmi2CallbackFreeMemoryTYPE(free))
                self.call("instantiate", self.slave.instantiate, callbacks=self._callbacks,
                          loggingOn=True)
            else:
                self.call("instantiate", self.slave.instantiate, loggingOn=True, logMessage=log)
        except Exception as error:
            self._remove_unzip_dir()
            if isinstance(error, FmuCallError):
                raise
            raise FmuCallError(name, f"instantiate ({self.path.name})", None, "failure",
                               [*self.log, LogRecord("fatal", None,
                                                     f"{type(error).__name__}: {error}")]
                               ) from error

    def call(self, what: str, function: Callable, *args, time: float | None = None,
             strict: bool = False, **kwargs) -> Any:
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
        """The log since ``before``; pythonfmu's fatal message repeating a logged cause left out."""
        new = self.logged - before
        records = list(self.log)[-new:] if new else []
        if any(r.cause for r in records):
            records = [r for r in records if r.category is not None or r.status != "fatal"]
        return records

    def fmi(self, name: str):
        return getattr(self.slave, CALLS.get(name, name) if self.fmi_version == 3 else name)

    def enter_initialization(self, start_time: float = 0.0) -> None:
        if self.fmi_version == 2:
            self.call("setupExperiment", self.slave.setupExperiment, startTime=start_time)
            self.call("enterInitializationMode", self.slave.enterInitializationMode)
        else:
            self.call("enterInitializationMode", self.slave.enterInitializationMode,
                      startTime=start_time)

    def reset(self) -> None:
        self.call("reset", self.slave.reset)

    def free(self) -> None:
        with contextlib.suppress(FMICallException):
            self.slave.terminate()
        self.slave.freeInstance()
        self._remove_unzip_dir()

    def _remove_unzip_dir(self) -> None:
        if self._owns_unzip_dir:
            shutil.rmtree(self.unzip_dir, ignore_errors=True)

    # Prepared calls: the raw FMI functions (fmpy's ``dll``) on preallocated ctypes arrays,
    # without fmpy's per-call wrapping, which costs more than the call itself.
    def _raw(self, verb: str, kind: str, vrs: list[int]) -> tuple[Any, Callable[[], None]]:
        reference, types = RAW_TYPES[self.fmi_version]
        name, ctype = types[kind]
        function = getattr(self.slave.dll, f"fmi{self.fmi_version}{verb.title()}{name}")
        component, n = self.slave.component, len(vrs)
        refs, values = (reference * n)(*vrs), (ctype * n)()
        counts = (n,) if self.fmi_version == 2 else (n, n)   # FMI 3.0: the value count too
        what = f"{verb}{name}"                               # a watchdog reads it here

        def run() -> None:
            before = self.logged
            status = function(component, refs, counts[0], values, *counts[1:])
            if status > 1:                      # discard, error, fatal
                raise FmuCallError(self.name, what, None, STATUS[status], self._since(before))
        return values, run

    def reader(self, vrs: list[int], kind: str = "Real") -> Callable[[], list]:
        values, run = self._raw("get", kind, vrs)

        def read() -> list:
            run()
            return values[:]
        return read

    def writer(self, vrs: list[int]):
        values, run = self._raw("set", "Real", vrs)

        def write(new: list[float]) -> None:
            values[:] = new
            run()
        return write

    def stepper(self):
        component, terminate = self.slave.component, fmi3Boolean()    # set by FMI 3.0 only
        if self.fmi_version == 2:
            do_step, rest = self.slave.dll.fmi2DoStep, ()
        else:            # noEarlierState, then eventHandlingNeeded, terminate, early, lastTime
            do_step = self.slave.dll.fmi3DoStep
            rest = byref(fmi3Boolean()), byref(terminate), byref(fmi3Boolean()), \
                byref(fmi3Float64())

        def step(t: float, h: float) -> None:
            before = self.logged
            status = do_step(component, t, h, True, *rest)
            if status > 1:
                raise FmuCallError(self.name, "doStep", t, STATUS[status], self._since(before))
            if terminate.value:
                raise FmuCallError(self.name, "doStep", t, "OK but asked to end the simulation "
                                   "(terminateSimulation)", self._since(before))
        return step
