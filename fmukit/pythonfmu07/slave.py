"""``Fmi2Entry``: the mixin that makes a ``ModelSlave`` an FMI 2.0 FMU of pythonfmu 0.7.
Every refusal is an exception: fmi2Fatal (pythonfmu 0.7's fmi2Discard would pass for an end)."""
from __future__ import annotations

import ctypes
from typing import Any, Callable
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Variability, Integer, Real
from pythonfmu import Fmi2Slave  # noqa: F401  fmukit.compose takes the base class from here
from pythonfmu import String
from pythonfmu.enums import Fmi2Status

from ..entry import fmi_entry
from ..registry import pythonfmu_variable
from ..variables import Var, describe
from . import ACTIVE, KNOWN_BINARIES

_TYPE = {float: Real, int: Integer, str: String}


class Fmi2Entry:
    """FMI 2.0 through pythonfmu 0.7: the version's half of an FMU's class."""
    API, FMI_VERSION = "fmi2", 2
    STATUS_ERROR, STATUS_FATAL = Fmi2Status.error, Fmi2Status.fatal
    RELEASES_ON_EXCEPTION = ACTIVE
    KNOWN_BINARIES, HEARS_UNKNOWN = KNOWN_BINARIES, False

    def fmi_variable(self, var: Var, getter: Callable[[], Any] | None) -> Any:
        return pythonfmu_variable(var, getter, _TYPE[var.kind], Fmi2Causality,
                                  Fmi2Variability, Fmi2Initial)

    @fmi_entry
    def setup_experiment(self, start_time: float, stop_time: float | None = None,
                         tolerance: float | None = None) -> None:
        self.sequence.require("SetupExperiment", "instantiated")
        self.start_time = start_time

    @fmi_entry
    def do_step(self, current_time: float, step_size: float) -> bool:
        self._step(current_time, step_size)
        return True

    @fmi_entry
    def set_real(self, vrs: list[int], values: list[float]) -> None:
        self._set_floats(vrs, values)

    @fmi_entry
    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        self._set(vrs, values, int)

    @fmi_entry
    def get_real(self, vrs: list[int]) -> list[float]:
        read = self.plans.real_reader(vrs)
        return super().get_real(vrs) if read is None else read()   # pythonfmu names a problem

    @fmi_entry
    def get_integer(self, vrs: list[int]) -> list[int]:
        read = self.plans.integer_reader(vrs)
        return super().get_integer(vrs) if read is None else read()

    def to_xml(self, model_options: dict[str, str] = dict()) -> Element:
        """pythonfmu's model description with what it leaves out (``describe``)."""
        root = super().to_xml(model_options)
        structure, unknowns = describe(root, self.variables, [
            e.find("Real" if v.is_real else "Integer")
            for e, v in zip(root.find("ModelVariables"), self.variables)],
            {v.name: i + 1 for i, v in enumerate(self.variables)})
        for tag, when in (("Outputs", 0), ("InitialUnknowns", 1)) if unknowns else ():
            listed = SubElement(structure, tag)
            for reference, depends in unknowns:
                SubElement(listed, "Unknown", index=reference, dependencies=" ".join(depends[when]))
        return root


def hold_namespace(namespace: dict[str, Any]) -> None:
    """One more reference on an FMU entry module's namespace each time it runs: pythonfmu
    0.7 reruns it at every instantiation and releases the namespace it was only lent."""
    if ACTIVE:
        ctypes.pythonapi.Py_IncRef(ctypes.py_object(namespace))
