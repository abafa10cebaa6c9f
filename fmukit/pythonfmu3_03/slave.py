"""``Fmi3Entry``: the mixin that makes a ``ModelSlave`` an FMI 3.0 FMU of pythonfmu3 0.3.4,
with the independent variable ``time``."""
from __future__ import annotations

from typing import Any, Callable
from xml.etree.ElementTree import Element, SubElement

from pythonfmu3 import Fmi3Causality, Fmi3Initial, Fmi3Status, Fmi3StepResult
from pythonfmu3 import Fmi3Slave  # noqa: F401  fmukit.compose takes the base class from here
from pythonfmu3 import Fmi3Variability, Float64, Int32, String

from ..entry import fmi_entry
from ..registry import pythonfmu_variable
from ..variables import Var, describe
from . import ACTIVE, KNOWN_BINARIES

_TYPE = {float: Float64, int: Int32, str: String}
_FROM_CLASS = ("description", "author", "license", "version", "copyright",
               "default_experiment")      # pythonfmu3 writes them from the instance only


def _refused_step() -> Fmi3StepResult:
    return Fmi3StepResult(status=Fmi3Status.error)


class Fmi3Entry:
    """FMI 3.0 through pythonfmu3 0.3.4: the version's half of an FMU's class."""
    API, FMI_VERSION = "fmi3", 3
    STATUS_ERROR, STATUS_FATAL = Fmi3Status.error, Fmi3Status.fatal
    RELEASES_ON_EXCEPTION = ACTIVE
    KNOWN_BINARIES, HEARS_UNKNOWN = KNOWN_BINARIES, True

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for attribute in _FROM_CLASS:
            setattr(self, attribute, getattr(type(self), attribute, None))
        self.start_time = None                 # pythonfmu3 drops it: messages name none

    def _before_variables(self) -> None:
        """``time`` at value reference 0: a variable's is its FMI 2.0 twin's plus one."""
        self.time = 0.0
        self.register_variable(Float64("time", causality=Fmi3Causality.independent,
                                       variability=Fmi3Variability.continuous,
                                       description="simulation time",
                                       getter=lambda: self.time))

    def fmi_variable(self, var: Var, getter: Callable[[], Any] | None) -> Any:
        return pythonfmu_variable(var, getter, _TYPE[var.kind], Fmi3Causality,
                                  Fmi3Variability, Fmi3Initial,
                                  **({"unit": var.unit} if var.is_real else {}))

    def log(self, msg: str, status: Fmi3Status = Fmi3Status.ok, category: str | None = None,
            debug: bool = False) -> None:
        """pythonfmu3's log, kept off the host's callback while its logging is off."""
        if self.host_log.hears():
            super().log(msg, status, category, debug)

    @fmi_entry(error_result=_refused_step)
    def do_step(self, current_time: float, step_size: float) -> Fmi3StepResult:
        self._step(current_time, step_size)
        self.time = current_time + step_size
        return Fmi3StepResult()

    @fmi_entry
    def set_float64(self, vrs: list[int], values: list[float]) -> None:
        self._set_floats(vrs, values)

    @fmi_entry
    def set_int32(self, vrs: list[int], values: list[int]) -> None:
        self._set(vrs, values, int)

    @fmi_entry
    def get_float64(self, vrs: list[int]) -> list[float]:
        read = self.plans.real_reader(vrs)
        return super().get_float64(vrs) if read is None else read()  # pythonfmu3 names a problem

    @fmi_entry
    def get_int32(self, vrs: list[int]) -> list[int]:
        read = self.plans.integer_reader(vrs)
        return super().get_int32(vrs) if read is None else read()

    def to_xml(self, model_options: dict[str, str] = dict()) -> Element:
        """pythonfmu3's model description with what it leaves out (``describe``; its bare
        <Output> is an algebraic loop to a master); ``time`` last, for an importer that
        reads dependencies as 1-based indices (OMSimulator)."""
        root = super().to_xml(model_options)
        listed = root.find("ModelVariables")
        elements = {e.get("name"): e for e in listed}
        for independent in [e for e in listed if e.get("causality") == "independent"]:
            listed.remove(independent)
            listed.append(independent)
        structure, unknowns = describe(root, self.variables,
                                       [elements[v.name] for v in self.variables],
                                       {v.name: vr for vr, v in self.registry.by_vr.items()})
        for tag, when in (("Output", 0), ("InitialUnknown", 1)):
            for reference, depends in unknowns:
                kinds = {"dependenciesKind": " ".join(["dependent"] * len(depends[when]))}
                SubElement(structure, tag, valueReference=reference,
                           dependencies=" ".join(depends[when]), **(kinds if depends[when] else {}))
        return root
