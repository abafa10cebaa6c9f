"""A thin, declarative layer over pythonfmu's Fmi2Slave.

An FMU class lists its variables once, as ``Var`` entries with unit, causality,
start value, valid range and, for outputs, the variables they depend on. From
that list this base class

- registers the variables with pythonfmu (parameters and inputs live as
  attributes of the slave, outputs are read from its model);
- writes a complete modelDescription.xml: unit definitions with degree display
  units, ``min``/``max``, ``initial="calculated"`` outputs, output
  ``dependencies`` (so masters see which outputs are not direct feedthrough) and
  ``InitialUnknowns``;
- follows the FMI 2.0 call sequence and refuses what breaks it;
- checks every parameter (at exitInitializationMode) and input (at each doStep)
  against its range, and rounds the time it is given to whole nanoseconds
  (``fmukit.timebase``);
- saves and restores the whole state (fmi2Get/SetFMUstate, serialisable).

Errors. pythonfmu 0.7 turns every Python exception into fmi2Fatal, and a False
return of do_step into fmi2Discard. Its C++ layer also releases the instance, its
class and its log queue once per exception and again at fmi2FreeInstance, a
use-after-free that crashes the host later. Every FMI entry point here therefore
passes through ``_fmi_entry``, which takes one extra reference on those three
objects before an exception leaves Python, so the host survives. With that:

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

The subclass supplies ``build_model`` (a model from the parameter attributes
alone), ``step_model`` and, if the initial state depends on inputs,
``start_model``; the model supplies ``snapshot``/``restore``.
"""
from __future__ import annotations

import ctypes
import functools
import json
import math
import operator
import os
import sys
from dataclasses import dataclass
from typing import Any, Callable, ClassVar
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import DefaultExperiment, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability
from pythonfmu import Integer, Real, String
from pythonfmu import __version__ as PYTHONFMU_VERSION
from pythonfmu.enums import Fmi2Status

from .timebase import MAX_TIME, nanoseconds, seconds
from .units import DISPLAY_UNIT, unit_definitions

_PYTHONFMU_TYPE = {float: Real, int: Integer, str: String}
_AFTER = {"instantiated": "fmi2Instantiate or fmi2Reset",
          "initialization": "fmi2EnterInitializationMode",
          "step": "fmi2ExitInitializationMode", "terminated": "fmi2Terminate"}
_RELEASES_ON_EXCEPTION = PYTHONFMU_VERSION == "0.7.0"


def _echo(slave: Fmi2Slave, message: str) -> None:
    """Also write an error to standard error if FMUKIT_LOG_STDERR is set.

    For hosts that drop FMU log messages (ecos 0.7 installs a no-op logger).
    """
    if os.environ.get("FMUKIT_LOG_STDERR"):
        print(f"[{slave.instance_name}] {message}", file=sys.stderr, flush=True)


def _fmi_entry(method):
    """Let an exception reach pythonfmu's C++ layer without corrupting the host."""
    @functools.wraps(method)
    def entry(self, *args):
        try:
            return method(self, *args)
        except Exception as error:
            _echo(self, f"{method.__name__}: {error!r}")
            if _RELEASES_ON_EXCEPTION:
                for obj in (self, type(self), self.log_queue):
                    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))
            raise
    return entry


@dataclass(frozen=True)
class Var:
    """One FMU variable, declared once. Build it with the class methods."""

    name: str
    causality: str                    # "parameter" | "input" | "output"
    unit: str = "1"                   # key of fmukit.units.UNITS (Real only)
    description: str = ""
    start: float | int | str | None = None
    kind: type = float                # float (Real), int (Integer) or str (String)
    depends: tuple[str, ...] = ()     # outputs: inputs and parameters they depend on
    initial_depends: tuple[str, ...] = ()     # outputs: further knowns, at initialisation only
    get: Callable[[Any], Any] | None = None   # outputs: value from the slave
    min: float = -math.inf            # inputs and parameters: the valid range, written to
    max: float = math.inf             # modelDescription.xml and enforced (NaN is never valid)

    @classmethod
    def parameter(cls, name: str, start: float | int | str, unit: str = "1",
                  description: str = "", min: float = -math.inf,
                  max: float = math.inf) -> Var:
        """A fixed parameter; its Python type (float, int, str) sets the FMI type."""
        return cls(name, "parameter", unit, description, start, type(start), min=min, max=max)

    @classmethod
    def input(cls, name: str, start: float, unit: str = "1", description: str = "",
              min: float = -math.inf, max: float = math.inf) -> Var:
        """A continuous Real input."""
        return cls(name, "input", unit, description, float(start), min=min, max=max)

    def check(self, value: Any) -> None:
        """ValueError naming this variable if a number is NaN, infinite or out of range."""
        if self.kind is str:
            return
        kind = "input" if self.causality == "input" else "parameter"
        if not math.isfinite(value):
            raise ValueError(f"{kind} {self.name} = {value} is not finite")
        if not self.min <= value <= self.max:
            raise ValueError(f"{kind} {self.name} = {value} is outside its range "
                             f"[{self.min:g}, {self.max:g}]")

    @classmethod
    def output(cls, name: str, unit: str = "1", description: str = "",
               depends: tuple[str, ...] = (), initial_depends: tuple[str, ...] = (),
               get: Callable[[Any], Any] | None = None, kind: type = float) -> Var:
        """An output read from the slave by ``get`` (default: the model's attribute).

        ``depends``: the inputs (direct feedthrough) and parameters it depends on;
        ``initial_depends``: inputs it depends on only at initialisation.
        """
        return cls(name, "output", unit, description, None, kind, depends, initial_depends,
                   get)

    @property
    def is_real(self) -> bool:
        return self.kind is float


class ModelSlave(Fmi2Slave):
    """Base of every FMU in this project; see the module docstring."""

    model_name: ClassVar[str]
    variables: ClassVar[tuple[Var, ...]]
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=400.0, step_size=0.1)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.modelName = self.model_name
        self.phase = "instantiated"
        self._model = None
        self._by_vr: dict[int, Var] = {}
        self._real_getters: dict[int, Callable[[], float]] = {}   # getReal's fast path
        self._model_attributes: dict[int, str] = {}  # outputs that are attributes of the model
        self._reads: dict[tuple[int, ...], Callable[[], list[float]]] = {}
        self._writes: dict[tuple[int, ...], tuple[str, ...]] = {}
        self._int_getters: dict[int, Callable[[], int]] = {}
        self._real_inputs: dict[int, str] = {}                   # setReal's fast path
        for var in self.variables:
            self._register(var)
        self._checked = [v for v in self.variables if v.causality != "output"]
        self._checked_inputs = [v for v in self._checked if v.causality == "input"]

    def _register(self, var: Var) -> None:
        kind = _PYTHONFMU_TYPE[var.kind]
        if var.causality == "output":
            get = var.get or (lambda slave, name=var.name: getattr(slave._model, name))

            def getter(get=get, undefined=math.nan if var.is_real else 0) -> Any:
                return self._output(get, undefined)
            sv = kind(var.name, causality=Fmi2Causality.output,
                      variability=(Fmi2Variability.continuous if var.is_real
                                   else Fmi2Variability.discrete),
                      initial=Fmi2Initial.calculated, description=var.description,
                      getter=getter)
        else:
            setattr(self, var.name, var.start)
            variability = (Fmi2Variability.fixed if var.causality == "parameter"
                           else Fmi2Variability.continuous)
            sv = kind(var.name, causality=Fmi2Causality[var.causality],
                      variability=variability, description=var.description)
        self.register_variable(sv)
        self._by_vr[sv.value_reference] = var
        if var.is_real:
            self._real_getters[sv.value_reference] = sv.getter
            if var.causality == "input":
                self._real_inputs[sv.value_reference] = var.name
            elif var.causality == "output" and var.get is None:
                self._model_attributes[sv.value_reference] = var.name
        elif var.kind is int:
            self._int_getters[sv.value_reference] = sv.getter

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
    def _require_phase(self, call: str, *phases: str) -> None:
        if self.phase not in phases:
            raise ValueError(f"{call} is not allowed in phase '{self.phase}' (FMI 2.0 allows "
                             f"it after {' or '.join(_AFTER[p] for p in phases)})")

    @_fmi_entry
    def enter_initialization_mode(self) -> None:
        self._require_phase("fmi2EnterInitializationMode", "instantiated")
        self.phase = "initialization"

    @_fmi_entry
    def exit_initialization_mode(self) -> None:
        self._require_phase("fmi2ExitInitializationMode", "initialization")
        for var in self._checked:             # the declared ranges, then the model's own rules
            if var.causality == "parameter":
                var.check(getattr(self, var.name))
        self._model = self._started_model()   # ValueError names a bad parameter or input
        self.phase = "step"

    @_fmi_entry
    def terminate(self) -> None:
        self._require_phase("fmi2Terminate", "step")
        self.phase = "terminated"

    @_fmi_entry
    def do_step(self, current_time: float, step_size: float) -> bool:
        if self.phase != "step":
            return self._refuse(f"doStep called in phase '{self.phase}': "
                                "call exitInitializationMode first, and not after terminate")
        if not (1e-9 <= step_size <= MAX_TIME and abs(current_time) <= MAX_TIME):
            return self._refuse(f"doStep at t = {current_time} with communication step "
                                f"{step_size}: the step must be at least 1 ns, and both within "
                                f"+-{MAX_TIME:g} s")
        try:
            for var in self._checked_inputs:
                var.check(getattr(self, var.name))
            # The time base of fmukit.timebase: whole nanoseconds, whatever the master.
            self.step_model(seconds(nanoseconds(current_time)), seconds(nanoseconds(step_size)))
        except ValueError as error:
            return self._refuse(f"doStep at t = {current_time}: {error}; step refused, "
                                "state unchanged")
        return True

    def _refuse(self, message: str) -> bool:
        self.log(message, Fmi2Status.error)
        _echo(self, message)
        return False

    # -- setters: refuse what the standard does not allow ----------------------
    def _check_settable(self, vrs: list[int]) -> None:
        for vr in vrs:
            var = self._by_vr.get(vr)
            if var is None:
                raise ValueError(f"no variable has value reference {vr}")
            if var.causality == "output":
                raise ValueError(f"{var.name} is an output and cannot be set")
            if var.causality == "parameter" and self.phase not in ("instantiated",
                                                                   "initialization"):
                raise ValueError(f"parameter {var.name} is fixed after initialisation "
                                 f"(phase '{self.phase}')")
            if self.phase == "terminated":
                raise ValueError(f"cannot set {var.name} after terminate")

    def _set(self, vrs: list[int], values: list, convert: type) -> None:
        self._check_settable(vrs)
        for vr, value in zip(vrs, values):
            var = self._by_vr[vr]
            if var.kind is not convert:
                raise ValueError(f"{var.name} is not of type {convert.__name__}")
            setattr(self, var.name, convert(value))
            if var.causality == "parameter":
                self._model = None

    @_fmi_entry
    def set_real(self, vrs: list[int], values: list[float]) -> None:
        key = tuple(vrs)
        names = self._writes.get(key)
        if names is None:           # inputs only: always settable until terminate
            inputs = self._real_inputs
            names = self._writes[key] = (tuple(inputs[vr] for vr in vrs)
                                         if all(vr in inputs for vr in vrs) else ())
        if names and self.phase != "terminated":
            for name, value in zip(names, values):
                setattr(self, name, float(value))
        else:
            self._set(vrs, values, float)

    @_fmi_entry
    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        self._set(vrs, values, int)

    @_fmi_entry
    def set_string(self, vrs: list[int], values: list[str]) -> None:
        self._set(vrs, values, str)

    # -- FMU state ---------------------------------------------------------------
    @_fmi_entry
    def _get_fmu_state(self) -> dict[str, Any]:
        return {
            "phase": self.phase,
            "values": {v.name: getattr(self, v.name) for v in self.variables
                       if v.causality != "output"},
            "model": self._model.snapshot() if self._model is not None else None,
        }

    @_fmi_entry
    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        if "invalid" in state:
            raise ValueError(f"cannot restore FMU state: {state['invalid']}")
        for name, value in state["values"].items():
            setattr(self, name, value)
        self.phase = state["phase"]
        self._model = None
        if state["model"] is not None:
            self._model = self.build_model()
            self._model.restore(state["model"])

    @staticmethod
    def _fmu_state_from_bytes(state: bytes) -> dict[str, Any]:
        # Called on the class, where an exception cannot be made safe: report it
        # through the state, and let _set_fmu_state refuse it.
        try:
            decoded = json.loads(state.decode("utf-8"))
            if not {"phase", "values", "model"} <= set(decoded):
                raise ValueError("not a state of this FMU")
            return decoded
        except (ValueError, UnicodeDecodeError, TypeError) as error:
            return {"invalid": f"serialized state unreadable ({error})"}

    @_fmi_entry
    def setup_experiment(self, start_time: float, stop_time: float | None = None,
                         tolerance: float | None = None) -> None:
        self._require_phase("fmi2SetupExperiment", "instantiated")

    @_fmi_entry
    def get_real(self, vrs: list[int]) -> list[float]:
        read = self._reads.get(tuple(vrs))
        if read is None:
            read = self._reads[tuple(vrs)] = self._compile_read(vrs)
        return read()

    def _compile_read(self, vrs: list[int]) -> Callable[[], list[float]]:
        """The fastest correct way to read these value references, built once."""
        if not all(vr in self._real_getters for vr in vrs):
            return lambda: Fmi2Slave.get_real(self, vrs)   # pythonfmu names the problem
        getters = [self._real_getters[vr] for vr in vrs]

        def each() -> list[float]:
            return [float(get()) for get in getters]
        if not all(vr in self._model_attributes for vr in vrs):
            return each
        attributes = operator.attrgetter(*(self._model_attributes[vr] for vr in vrs))

        def model_attributes() -> list[float]:     # the ship's states: one C-level call
            model = self._model
            if model is None:
                return each()
            values = attributes(model)
            return list(values) if len(vrs) > 1 else [values]
        return model_attributes

    @_fmi_entry
    def get_integer(self, vrs: list[int]) -> list[int]:
        getters = self._int_getters
        if all(vr in getters for vr in vrs):
            return [int(getters[vr]()) for vr in vrs]
        return super().get_integer(vrs)         # pythonfmu names the problem

    @_fmi_entry
    def get_string(self, vrs: list[int]) -> list[str]:
        return super().get_string(vrs)

    @_fmi_entry
    def get_boolean(self, vrs: list[int]) -> list[bool]:
        return super().get_boolean(vrs)

    @_fmi_entry
    def set_boolean(self, vrs: list[int], values: list[bool]) -> None:
        raise ValueError("this FMU has no Boolean variables")

    # -- modelDescription.xml ------------------------------------------------------
    def to_xml(self, model_options: dict[str, str] = dict()) -> Element:
        root = super().to_xml(model_options)
        index = {v.name: i + 1 for i, v in enumerate(self.variables)}
        for element, var in zip(root.find("ModelVariables"), self.variables):
            if var.kind is str:
                continue
            typed = element.find("Real" if var.is_real else "Integer")
            if var.is_real:
                if var.start is not None:
                    typed.set("start", repr(float(var.start)))   # shortest exact form
                typed.set("unit", var.unit)
                if var.unit in DISPLAY_UNIT:
                    typed.set("displayUnit", DISPLAY_UNIT[var.unit])
            for bound in ("min", "max"):
                value = getattr(var, bound)
                if math.isfinite(value):
                    typed.set(bound, repr(var.kind(value)))
        used = {v.unit for v in self.variables if v.is_real}
        root.insert(list(root).index(root.find("CoSimulation")) + 1, unit_definitions(used))

        structure = root.find("ModelStructure")
        structure.clear()
        outputs = [v for v in self.variables if v.causality == "output"]
        if outputs:
            causality = {v.name: v.causality for v in self.variables}
            listed = SubElement(structure, "Outputs")
            for v in outputs:
                inputs = [d for d in v.depends if causality[d] == "input"]
                SubElement(listed, "Unknown", index=str(index[v.name]),
                           dependencies=_indices(inputs, index))
            initial = SubElement(structure, "InitialUnknowns")
            for v in outputs:
                SubElement(initial, "Unknown", index=str(index[v.name]),
                           dependencies=_indices(v.depends + v.initial_depends, index))
        return root


def _indices(names: tuple[str, ...] | list[str], index: dict[str, int]) -> str:
    """Ordered, space-separated 1-based indices, as ModelStructure wants them."""
    return " ".join(str(i) for i in sorted(index[n] for n in names))
