"""``ModelSlave``: the base of every FMU in this project, a thin layer over pythonfmu's Fmi2Slave.

An FMU class lists its variables once, as ``Var`` entries (``fmukit.variables``)
with unit, causality, start value, valid range and, for outputs, the variables
they depend on, and supplies ``build_model`` (a model from the parameter
attributes alone), ``step_model`` and, if the initial state depends on inputs,
``start_model``; the model supplies ``snapshot``/``restore``. The parts, one job each:

- ``fmukit.registry``: the variables registered with pythonfmu, by value reference;
- ``fmukit.sequence``: the FMI 2.0 call sequence, which refuses calls out of order;
- ``fmukit.variables``: the range checks of every parameter (at
  exitInitializationMode) and input (at each doStep);
- ``fmukit.fastpath``: getReal, setReal and getInteger planned once per list of
  value references;
- ``fmukit.state``: saving and restoring the whole state (serialisable);
- ``fmukit.model_description``: a complete modelDescription.xml;
- ``fmukit.entry``: every FMI entry point made safe against pythonfmu 0.7's error path.

What a host sees, with pythonfmu 0.7 (which turns every Python exception into
fmi2Fatal, and a False return of do_step into fmi2Discard):

- invalid parameters: the range check or the model raises ValueError at
  exitInitializationMode, reported as fmi2Fatal with the message naming the
  parameter;
- invalid inputs, step sizes, or doStep out of sequence: the step is refused with
  fmi2Discard and an error log naming the cause; the state is left as it was,
  so a master may correct the input and retry;
- other calls out of sequence, setting an output, or a fixed parameter after
  initialisation: fmi2Fatal with a message naming the call or variable; nothing
  is applied;
- reading an output never fails: what cannot be evaluated reads NaN.

Time is rounded to whole nanoseconds before the model sees it (``fmukit.timebase``).
"""
from __future__ import annotations

from typing import Any, Callable, ClassVar
from xml.etree.ElementTree import Element

from pythonfmu import DefaultExperiment, Fmi2Slave
from pythonfmu.enums import Fmi2Status

from . import model_description, state
from .entry import echo, fmi_entry
from .fastpath import FastPaths
from .registry import Registry
from .sequence import CallSequence
from .timebase import MAX_TIME, nanoseconds, seconds
from .variables import Var

__all__ = ["ModelSlave", "Var"]


class ModelSlave(Fmi2Slave):
    """Base of every FMU in this project; see the module docstring."""

    model_name: ClassVar[str]
    variables: ClassVar[tuple[Var, ...]]
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=400.0, step_size=0.1)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.modelName = self.model_name
        self.sequence = CallSequence()
        self._model = None
        self.registry = Registry(self, self.variables, self._output)
        self._fast = FastPaths(self, self.registry)
        self._parameters = [v for v in self.variables if v.causality == "parameter"]
        self._inputs = [v for v in self.variables if v.causality == "input"]

    # -- model ---------------------------------------------------------------
    def build_model(self) -> Any:
        """A fresh model from the current parameter attributes."""
        raise NotImplementedError

    def step_model(self, t: float, h: float) -> None:
        """Advance the model from t to t + h with the current inputs."""
        raise NotImplementedError

    def start_model(self, model: Any) -> None:
        """Set a model's initial state from the inputs seen at initialisation (default: none).

        Kept apart from build_model, which depends on parameters only: restoring a saved
        state rebuilds the model, and must not depend on the inputs of the moment.
        """

    def _started_model(self) -> Any:
        model = self.build_model()
        self.start_model(model)
        return model

    def _output(self, get: Callable[[Any], Any], undefined: Any) -> Any:
        """An output's value, or NaN (0 if Integer) when it cannot be evaluated.

        A read never fails: a failed getReal aborts some hosts (libcosim throws
        from a worker thread). Masters read outputs during initialisation, when
        parameters may still be invalid, and feedthrough outputs are evaluated from
        inputs that may be invalid; then the output is undefined, and the call
        that commits (exitInitializationMode, doStep) refuses with a message. A
        master that ignores those statuses still sees NaN outputs.
        """
        try:
            if self._model is None:
                self._model = self._started_model()
            return get(self)
        except (ValueError, ArithmeticError):
            return undefined

    @property
    def model(self) -> Any:
        """The model; before initialisation, built from the parameters as they are."""
        if self._model is None:
            self._model = self._started_model()
        return self._model

    # -- FMI call sequence -----------------------------------------------------
    @fmi_entry
    def setup_experiment(self, start_time: float, stop_time: float | None = None,
                         tolerance: float | None = None) -> None:
        self.sequence.require("fmi2SetupExperiment", "instantiated")

    @fmi_entry
    def enter_initialization_mode(self) -> None:
        self.sequence.require("fmi2EnterInitializationMode", "instantiated")
        self.sequence.phase = "initialization"

    @fmi_entry
    def exit_initialization_mode(self) -> None:
        self.sequence.require("fmi2ExitInitializationMode", "initialization")
        for var in self._parameters:          # the declared ranges, then the model's own rules
            var.check(getattr(self, var.name))
        self._model = self._started_model()   # ValueError names a bad parameter or input
        self.sequence.phase = "step"

    @fmi_entry
    def terminate(self) -> None:
        self.sequence.require("fmi2Terminate", "step")
        self.sequence.phase = "terminated"

    @fmi_entry
    def do_step(self, current_time: float, step_size: float) -> bool:
        refusal = self.sequence.step_refusal()
        if refusal:
            return self._refuse(refusal)
        if not (1e-9 <= step_size <= MAX_TIME and abs(current_time) <= MAX_TIME):
            return self._refuse(f"doStep at t = {current_time} with communication step "
                                f"{step_size}: the step must be at least 1 ns, and both within "
                                f"+-{MAX_TIME:g} s")
        try:
            for var in self._inputs:
                var.check(getattr(self, var.name))
            # The time base of fmukit.timebase: whole nanoseconds, whatever the master.
            self.step_model(seconds(nanoseconds(current_time)), seconds(nanoseconds(step_size)))
        except ValueError as error:
            return self._refuse(f"doStep at t = {current_time}: {error}; step refused, "
                                "state unchanged")
        return True

    def _refuse(self, message: str) -> bool:
        self.log(message, Fmi2Status.error)
        echo(self, message)
        return False

    # -- setters: refuse what the standard does not allow ----------------------
    def _set(self, vrs: list[int], values: list, convert: type) -> None:
        for vr in vrs:
            self.sequence.check_settable(self.registry.var(vr))
        for vr, value in zip(vrs, values):
            var = self.registry.by_vr[vr]
            if var.kind is not convert:
                raise ValueError(f"{var.name} is not of type {convert.__name__}")
            setattr(self, var.name, convert(value))
            if var.causality == "parameter":
                self._model = None

    @fmi_entry
    def set_real(self, vrs: list[int], values: list[float]) -> None:
        names = self._fast.input_names(vrs)   # inputs only: always settable until terminate
        if names and self.sequence.phase != "terminated":
            for name, value in zip(names, values):
                setattr(self, name, float(value))
        else:
            self._set(vrs, values, float)

    @fmi_entry
    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        self._set(vrs, values, int)

    @fmi_entry
    def set_string(self, vrs: list[int], values: list[str]) -> None:
        self._set(vrs, values, str)

    @fmi_entry
    def set_boolean(self, vrs: list[int], values: list[bool]) -> None:
        raise ValueError("this FMU has no Boolean variables")

    # -- getters ---------------------------------------------------------------------
    @fmi_entry
    def get_real(self, vrs: list[int]) -> list[float]:
        read = self._fast.real_reader(vrs)
        return read() if read is not None else super().get_real(vrs)  # pythonfmu names it

    @fmi_entry
    def get_integer(self, vrs: list[int]) -> list[int]:
        values = self._fast.integers(vrs)
        return values if values is not None else super().get_integer(vrs)

    @fmi_entry
    def get_string(self, vrs: list[int]) -> list[str]:
        return super().get_string(vrs)

    @fmi_entry
    def get_boolean(self, vrs: list[int]) -> list[bool]:
        return super().get_boolean(vrs)

    # -- FMU state ---------------------------------------------------------------
    @fmi_entry
    def _get_fmu_state(self) -> dict[str, Any]:
        return state.capture(self)

    @fmi_entry
    def _set_fmu_state(self, saved: dict[str, Any]) -> None:
        state.restore(self, saved)

    @staticmethod
    def _fmu_state_from_bytes(data: bytes) -> dict[str, Any]:
        return state.decode(data)

    # -- modelDescription.xml ------------------------------------------------------
    def to_xml(self, model_options: dict[str, str] = dict()) -> Element:
        return model_description.complete(super().to_xml(model_options), self.variables)
