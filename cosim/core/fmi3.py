"""The master's FMI 3.0 backend: an FMI 3.0 co-simulation FMU through fmpy's FMU3Slave.

``Fmu3Instance`` is what ``cosim.core.fmi.FmuInstance`` gives for an FMU whose
fmiVersion is 3.0: the same interface as the FMI 2.0 instance, the master's call
names mapped to FMI 3.0's (setReal -> setFloat64, getInteger -> getInt32; ``CALLS``).
The differences it absorbs: no setupExperiment (the start time goes to
enterInitializationMode); the raw get/set functions take a value count besides the
count of value references; fmi3DoStep has four outputs (eventHandlingNeeded,
terminateSimulation, earlyReturn, lastSuccessfulTime): a step that asks to end the
simulation is a failure of the run (FmuCallError), and the others mean nothing without
event mode or early return, which it does not ask for; the logger takes no component
argument, and pythonfmu3 logs its own messages with the category "" (no category,
None, as pythonfmu's FMI 2.0 ones). The independent variable ``time`` that FMI 3.0
requires is no variable of the master's (``FmuInstance.variables`` leaves it out).
"""
from __future__ import annotations

from ctypes import byref

from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64, fmi3Int32, fmi3ValueReference

from .fmi import FmuInstance
from .instance import FmuCallError

CALLS = {"setReal": "setFloat64", "getReal": "getFloat64",
         "setInteger": "setInt32", "getInteger": "getInt32",
         "getFMUstate": "getFMUState", "setFMUstate": "setFMUState",
         "freeFMUstate": "freeFMUState", "serializeFMUstate": "serializeFMUState",
         "deSerializeFMUstate": "deserializeFMUState"}
"""The master's (FMI 2.0) call names that FMI 3.0 names otherwise; the rest are the same."""


class Fmu3Instance(FmuInstance):
    """An FMI 3.0 co-simulation FMU through fmpy's FMU3Slave."""

    def _instantiate(self) -> None:
        self.slave = FMU3Slave(guid=self.description.guid, unzipDirectory=self.unzip_dir,
                               modelIdentifier=self.description.coSimulation.modelIdentifier,
                               instanceName=self.name)
        self.call("instantiate", self.slave.instantiate, loggingOn=True,
                  logMessage=self._on_log)

    def _on_log(self, env, status, category, message) -> None:
        self._log(status, category or None, message)       # pythonfmu3's own: b""

    def fmi(self, name: str):
        return getattr(self.slave, CALLS.get(name, name))

    def do_step(self, t: float, h: float) -> None:
        before = self.logged
        _, terminate, _, _ = self.call("doStep", self.slave.doStep, t, h, time=t)
        if terminate:
            raise self._terminated(t, before)

    def _terminated(self, t: float, before: int) -> FmuCallError:
        """What a step that asks to end the simulation (terminateSimulation) raises: the
        run cannot go on without this FMU."""
        return FmuCallError(self.name, "doStep", t, "OK but asked to end the simulation "
                            "(terminateSimulation)", self._since(before))

    def enter_initialization(self, start_time: float = 0.0) -> None:
        self.call("enterInitializationMode", self.slave.enterInitializationMode,
                  startTime=start_time)

    def reader(self, vrs: list[int]):
        return self._getter("fmi3GetFloat64", fmi3Float64, vrs)

    def integer_reader(self, vrs: list[int]):
        return self._getter("fmi3GetInt32", fmi3Int32, vrs)

    def _getter(self, function: str, ctype, vrs: list[int]):
        get, instance = getattr(self.slave.dll, function), self.slave.component
        n = len(vrs)
        refs, values = (fmi3ValueReference * n)(*vrs), (ctype * n)()
        what = function.removeprefix("fmi3")

        def read() -> list:
            before = self.logged
            status = get(instance, refs, n, values, n)
            if status:
                self._status(what, status, before)
            return values[:]
        return read

    def writer(self, vrs: list[int]):
        set_, instance = self.slave.dll.fmi3SetFloat64, self.slave.component
        n = len(vrs)
        refs, values = (fmi3ValueReference * n)(*vrs), (fmi3Float64 * n)()

        def write(new: list[float]) -> None:
            values[:] = new
            before = self.logged
            status = set_(instance, refs, n, values, n)
            if status:
                self._status("setFloat64", status, before)
        return write

    def stepper(self):
        do_step, instance = self.slave.dll.fmi3DoStep, self.slave.component
        terminate = fmi3Boolean()
        event, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Float64()
        pointers = byref(event), byref(terminate), byref(early), byref(last)
        no_earlier_state = fmi3Boolean(True)

        def step(t: float, h: float) -> None:
            before = self.logged
            status = do_step(instance, t, h, no_earlier_state, *pointers)
            if status:
                self._status("doStep", status, before, t)
            if terminate.value:
                raise self._terminated(t, before)
        return step
