"""``ModelSlave``: the base of every FMU here (FMI 2.0 and 3.0) and its FMI call sequence.
A failed FMU reads NaN and refuses every step with the first reason until reset, so a host
that ignores statuses cannot pass the run off as results (docs/robustness.md)."""
from __future__ import annotations

import json
import signal
from dataclasses import dataclass
from typing import Any, Callable, ClassVar, NoReturn

from . import hostsignals
from .entry import HostLog, fmi_entry
from .refusals import CAUSES, Refused, explain, naming
from .registry import Registry
from .timebase import MAX_TIME, on_time_base
from .variables import Var, range_check

__all__ = ["DefaultExperiment", "ModelSlave", "Refused", "Var"]

CATEGORIES = {f"fmukit.{cause}": f"Refused: {meaning}." for cause, meaning in CAUSES.items()}
_AFTER = {"instantiated": "{api}{instantiate} or {api}Reset",
          "initialization": "{api}EnterInitializationMode",
          "step": "{api}ExitInitializationMode", "terminated": "{api}Terminate"}
_INSTANTIATE = {"fmi2": "Instantiate", "fmi3": "InstantiateCoSimulation"}


class CallSequence:
    """The phase of one FMU instance (instantiated -> initialization -> step -> terminated;
    reset makes a new slave) and what the standard allows in it."""

    def __init__(self, api: str, phase: str = "instantiated"):
        self.api, self.phase = api, phase

    def require(self, call: str, *phases: str) -> None:
        """Refused naming the call and the phase unless the phase is one of ``phases``."""
        if self.phase not in phases:
            after = " or ".join(_AFTER[p].format(api=self.api, instantiate=_INSTANTIATE[self.api])
                                for p in phases)
            raise Refused(f"{self.api}{call} is not allowed in phase '{self.phase}' (FMI "
                          f"{self.api[3:]}.0 allows it after {after})", "call")

    def check_settable(self, var: Var) -> None:
        """Refused naming ``var`` if the standard forbids setting it now."""
        if var.causality == "output":
            raise Refused(f"{var.name} is an output and cannot be set", "call", var.name)
        if var.causality == "parameter" and not var.tunable and \
                self.phase not in ("instantiated", "initialization"):
            raise Refused(f"parameter {var.name} is fixed after initialisation "
                          f"(phase '{self.phase}')", "call", var.name)
        if self.phase == "terminated":
            raise Refused(f"cannot set {var.name} after terminate", "call", var.name)


@dataclass(frozen=True)
class DefaultExperiment:
    """The experiment the model description proposes (s), in either FMI version."""

    start_time: float | None = None
    stop_time: float | None = None
    step_size: float | None = None
    tolerance: float | None = None


class ModelSlave:
    """Base of every FMU: it lists its ``variables`` and supplies ``build_model`` (from the
    parameters alone), ``step_model`` and, if the initial state depends on inputs,
    ``start_model``; the model supplies ``snapshot``/``restore``."""

    model_name: ClassVar[str]
    variables: ClassVar[tuple[Var, ...]]
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=400.0, step_size=0.1)
    # The adapter gives API, STATUS_ERROR, STATUS_FATAL, RELEASES_ON_EXCEPTION, KNOWN_BINARIES,
    # HEARS_UNKNOWN (does the host of another binary hear?) and fmi_variable(var, getter).

    def __init__(self, **kwargs):
        super().__init__(**kwargs)            # pythonfmu's slave, next in the FMU class's MRO
        self.modelName = self.model_name
        self.log_categories = {**self.log_categories, **CATEGORIES}
        self.sequence = CallSequence(self.API)
        self.host_log = HostLog(kwargs, self.KNOWN_BINARIES, self.HEARS_UNKNOWN)
        self.failure: str | None = None       # why the FMU failed; until reset
        self.failure_cause = "model"          # its cause (fmukit.refusals.CAUSES)
        self.start_time: float | None = 0.0   # of the experiment, for messages (None: unknown)
        hostsignals.defer_host_handlers()
        self._model = None
        self._before_variables()
        self.registry = self.plans = Registry(self, self.variables, self._output)
        self._check_inputs = range_check(tuple(v for v in self.variables
                                               if v.causality == "input"))

    def _before_variables(self) -> None:     # the adapter's, registered first
        pass

    def build_model(self) -> Any:
        """A fresh model from the current parameter attributes."""
        raise NotImplementedError

    def step_model(self, t: float, h: float) -> None:
        """Advance the model from t to t + h with the current inputs."""
        raise NotImplementedError

    def tune_model(self, name: str) -> None:      # tunable parameter ``name``, set mid-run
        setattr(self.model, name, getattr(self, name))

    def start_model(self, model: Any) -> None:
        """Set a model's initial state from the inputs (a restored state does not use them)."""

    def _started_model(self) -> Any:
        model = self.build_model()
        self.start_model(model)
        return model

    @property
    def model(self) -> Any:
        """The model; before initialisation, built from the parameters as they are."""
        if self._model is None:
            self._model = self._started_model()
        return self._model

    def _output(self, get: Callable[[Any], Any], undefined: Any) -> Any:
        """An output's value, else ``undefined``: a read never fails (libcosim aborts)."""
        if self.failure:
            return undefined
        try:
            return get(self)
        except (ValueError, ArithmeticError) as error:
            if self.sequence.phase == "step":
                self._unevaluable(get, error)
            return undefined

    def _unevaluable(self, get: Callable[[Any], Any], error: Exception) -> None:
        """Fail the FMU for an output it cannot evaluate from valid inputs."""
        try:
            self._check_inputs(self)
        except ValueError:
            return
        output = next((f"output {v.name}" for v in self.variables if v.get is get), "an output")
        self._report(f"{output} could not be evaluated from valid inputs: {explain(error)}; "
                     "the FMU has failed", "model")

    def _report(self, failure: str, cause: str) -> None:
        """Fail the FMU for ``failure`` and tell the user now; the next doStep refuses."""
        self.failure, self.failure_cause = failure, cause
        self.log(naming(self.instance_name, failure), self.STATUS_ERROR, f"fmukit.{cause}")
        self.host_log.tell(self.instance_name, failure)

    def _fail(self, reason: str, cause: str, error: BaseException | None = None) -> NoReturn:
        self.failure, self.failure_cause = reason, cause
        raise Refused(reason, cause) from error

    def interrupted(self, where: str, error: BaseException) -> Refused:
        """Fail the FMU for a BaseException (Ctrl-C, a ``signal``) in ``where``: its Refused."""
        number = getattr(error, "signal",
                         signal.SIGINT if isinstance(error, KeyboardInterrupt) else None)
        if not self.failure:
            cause = (explain(error) if number is None
                     else f"interrupted by {signal.Signals(number).name}")
            self.failure = f"{where}: {cause}; the FMU has failed"
            self.failure_cause = "interrupted"
        return Refused(self.failure, self.failure_cause)

    @fmi_entry
    def enter_initialization_mode(self) -> None:
        self.sequence.require("EnterInitializationMode", "instantiated")
        self.sequence.phase = "initialization"

    @fmi_entry
    def exit_initialization_mode(self) -> None:
        self.sequence.require("ExitInitializationMode", "initialization")
        self.sequence.phase = "step"
        try:
            for var in self.variables:        # the declared ranges, then the model's own rules
                if var.causality == "parameter":
                    var.check(getattr(self, var.name))
            self._model = self._started_model()   # ValueError names a bad parameter or input
        except Exception as error:            # reported now, refused at the first step
            at = "" if self.start_time is None else f" at t = {self.start_time}"
            why = str(error) if isinstance(error, ValueError) else explain(error)
            self._report(f"exitInitializationMode{at}: {why}; the FMU has failed",
                         error.cause if isinstance(error, Refused) else "parameter")

    @fmi_entry
    def terminate(self) -> None:
        if not self.failure:                  # a failed FMU may be terminated in any phase
            self.sequence.require("Terminate", "step")
        self.sequence.phase = "terminated"

    def _step(self, current_time: float, step_size: float) -> None:
        if self.failure:
            raise Refused(self.failure, self.failure_cause)
        if self.sequence.phase != "step":     # like any call out of sequence: nothing done
            raise Refused(f"doStep called in phase '{self.sequence.phase}': call "
                          "exitInitializationMode first, and not after terminate", "call")
        if not (0.0 < step_size <= MAX_TIME and abs(current_time) <= MAX_TIME):
            self._fail(f"doStep at t = {current_time} with communication step {step_size}: the "
                       f"step must be positive, and both within +-{MAX_TIME:g} s", "step")
        try:
            self._check_inputs(self)
            h = on_time_base(step_size)       # under 0.5 ns (OMSimulator's last): none
            if h > 0.0:
                self.step_model(on_time_base(current_time), h)
        except ValueError as error:
            self._fail(f"doStep at t = {current_time}: {error}; the FMU has failed (its "
                       f"outputs read NaN until {self.API}Reset)",
                       error.cause if isinstance(error, Refused) else "model")
        except Exception as error:            # the model's own exception
            self._fail(f"doStep at t = {current_time}: {explain(error)}", "model", error)
        except BaseException as error:        # Ctrl-C or the like, raised in this FMU's code
            raise self.interrupted(f"doStep at t = {current_time}", error) from None

    def _set(self, vrs: list[int], values: list, convert: type) -> None:
        for vr in vrs:
            if vr not in self.registry.by_vr:
                raise ValueError(f"no variable has value reference {vr}")
            self.sequence.check_settable(self.registry.by_vr[vr])
        for vr, value in zip(vrs, values):
            var = self.registry.by_vr[vr]
            if var.kind is not convert:
                raise Refused(f"{var.name} is not of type {convert.__name__}", "call", var.name)
            if var.causality == "parameter" and self.sequence.phase == "step":
                _tune(self, var, convert(value))  # a tunable one, between steps
                continue
            setattr(self, var.name, convert(value))
            if var.causality == "parameter":
                self._model = None

    def _set_floats(self, vrs: list[int], values: list[float]) -> None:
        write = self.plans.input_writer(vrs)  # inputs only: always settable until terminate
        if write is None:
            self._set(vrs, values, float)
        else:
            write(values)

    @fmi_entry
    def set_string(self, vrs: list[int], values: list[str]) -> None:
        self._set(vrs, values, str)

    @fmi_entry
    def set_boolean(self, vrs: list[int], values: list[bool]) -> None:
        raise Refused("this FMU has no Boolean variables", "call")

    @fmi_entry
    def get_string(self, vrs: list[int]) -> list[str]:
        return super().get_string(vrs)

    @fmi_entry
    def get_boolean(self, vrs: list[int]) -> list[bool]:
        return super().get_boolean(vrs)

    @fmi_entry
    def _get_fmu_state(self) -> dict[str, Any]:
        """The whole state, which pythonfmu serialises as JSON; the model's: its ``snapshot()``."""
        return {"phase": self.sequence.phase,
                "values": {v.name: getattr(self, v.name) for v in self.vars.values()
                           if v.causality.name != "output"},
                "model": self._model.snapshot() if self._model is not None else None,
                "failure": self.failure, "failure_cause": self.failure_cause}

    @fmi_entry
    def _set_fmu_state(self, saved: dict[str, Any]) -> None:
        """Back to a saved state: the model rebuilt and handed its snapshot (bit for bit)."""
        if "invalid" in saved:
            raise ValueError(f"cannot restore FMU state: {saved['invalid']}")
        for name, value in saved["values"].items():
            setattr(self, name, value)
        self.sequence.phase = saved["phase"]
        self.failure, self.failure_cause = saved.get("failure"), saved.get("failure_cause", "model")
        self._model = None
        if saved["model"] is not None:
            self._model = self.build_model()
            self._model.restore(saved["model"])

    @staticmethod
    def _fmu_state_from_bytes(data: bytes) -> dict[str, Any]:
        """A serialised state, or ``{"invalid": why}`` for ``_set_fmu_state`` to refuse
        (pythonfmu calls this on the class, where an exception cannot be made safe)."""
        try:
            decoded = json.loads(data.decode("utf-8"))
            if not {"phase", "values", "model"} <= set(decoded):
                raise ValueError("not a state of this FMU")
            return decoded
        except (ValueError, UnicodeDecodeError, TypeError) as error:
            return {"invalid": f"serialized state unreadable ({error})"}


def _tune(slave: ModelSlave, var: Var, value: Any) -> None:
    """Tunable parameter ``var`` set between steps, taken whole or not at all: checked against
    its range, then the model takes it (``tune_model``); a refusal names it."""
    var.check(value)
    before = getattr(slave, var.name)
    setattr(slave, var.name, value)
    try:
        slave.tune_model(var.name)
    except ValueError:
        setattr(slave, var.name, before)
        raise
