"""``ModelSlave``: the base of every FMU in this project, the same for FMI 2.0 and FMI 3.0.

An FMU class lists its variables once, as ``Var`` entries (``fmukit.variables``)
with unit, causality, start value, valid range and, for outputs, the variables
they depend on, and supplies ``build_model`` (a model from the parameter
attributes alone), ``step_model`` and, if the initial state depends on inputs,
``start_model``; the model supplies ``snapshot``/``restore``. The parts, one job each:

- ``fmukit.registry``: the variables registered with pythonfmu, by value reference;
- ``fmukit.sequence``: the call sequence, which refuses calls out of order;
- ``fmukit.variables``: the range checks of every parameter (at
  exitInitializationMode) and input (at each doStep);
- ``fmukit.fastpath``: reading Reals and Integers and setting Real inputs planned once
  per list of value references (``plans``, which a host in the same process may call);
- ``fmukit.state``: saving and restoring the whole state (serialisable);
- ``fmukit.refusals``: how a call is refused, and the message that says why;
- ``fmukit.entry``: every FMI entry point made safe against pythonfmu's error path;
  ``fmukit.hostsignals``: the host's Ctrl-C handled in the host's code, not inside the FMU.

A ``ModelSlave`` is no FMU by itself: which FMI version, and which pythonfmu, is the
adapter's, a mixin composed with the model's class and pythonfmu's slave class by the
FMU's entry module (written by the build) or by ``fmukit.compose.fmu_class``:
``fmukit.pythonfmu07`` (FMI 2.0, pythonfmu 0.7.0) and ``fmukit.pythonfmu3_03`` (FMI 3.0,
pythonfmu3 0.3.4). Each supplies the typed getters and setters, doStep's result,
the pythonfmu variable of a ``Var`` (``fmi_variable``), the statuses, where errors reach
the user when the host does not listen (``_host_log``), and the completion of
modelDescription.xml, with what is owed to its pythonfmu's defects.

What a host sees. pythonfmu 0.7 can return fmi2OK, fmi2Fatal (any Python
exception) and fmi2Discard with fmi2Terminated true (do_step returning False),
which hosts such as fmpy take for the model's normal end: a refused step would
pass for a short, successful run. So every FMI 2.0 refusal raises, and is fmi2Fatal,
the only failure status there is to give (docs/robustness.md argues it). pythonfmu3
passes on the status doStep returns: an FMI 3.0 refused step is fmi3Error, which
allows fmi3Reset; every other FMI 3.0 refusal is fmi3Fatal, as pythonfmu3 makes
every exception.

- invalid parameters: exitInitializationMode reports them (an error
  message naming the parameter) and the FMU has failed; the first doStep
  then fails with that message. Not exitInitializationMode itself: OSP
  libcosim terminates its host process when that call fails;
- invalid inputs or step sizes, or an exception in the model: doStep fails
  naming the cause (for an exception other than a ValueError, the file and line of the
  model's code it came from: ``fmukit.refusals.explain``), and the FMU has failed;
- once failed, every output reads NaN and every step is refused with the first
  reason, until reset, so that a host that ignores statuses (ecos) still
  cannot pass the rest of the run off as results;
- calls out of sequence (doStep included), setting an output or a fixed
  parameter after initialisation: refused naming the call or variable; nothing
  is applied, and the FMU goes on as before;
- reading an output never fails: what cannot be evaluated reads NaN (and, from valid
  inputs while stepping, fails the FMU, the next doStep refusing with where it came
  from).

The reason, beginning with the FMU's instance name (libcosim's log shows neither the
instance nor the call), reaches the user through the host's logger when it listens,
under the category ``fmukit.<cause>`` that says what was refused
(``fmukit.refusals.CAUSES``), and on standard error when it does not (the adapter's
``hostlog``).

Time is rounded to whole nanoseconds before the model sees it (``fmukit.timebase``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, ClassVar, NoReturn

from . import hostsignals, state
from .entry import fmi_entry
from .fastpath import FastPaths
from .refusals import CAUSES, Refused, explain, naming, reason
from .registry import Registry
from .sequence import CallSequence
from .timebase import MAX_TIME, on_time_base
from .variables import Var, range_check

__all__ = ["DefaultExperiment", "ModelSlave", "Refused", "Var"]

CATEGORIES = {f"fmukit.{cause}": f"Refused: {meaning}." for cause, meaning in CAUSES.items()}
"""The log categories of every refusal's cause, which each adapter declares."""


@dataclass(frozen=True)
class DefaultExperiment:
    """The experiment the model description proposes (s), in either FMI version."""

    start_time: float | None = None
    stop_time: float | None = None
    step_size: float | None = None
    tolerance: float | None = None


class ModelSlave:
    """Base of every FMU in this project; see the module docstring."""

    model_name: ClassVar[str]
    variables: ClassVar[tuple[Var, ...]]
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=400.0, step_size=0.1)
    # The adapter's: "fmi2" or "fmi3"; the statuses of an error and of a fatal refusal;
    # whether its binary releases the instance once per exception (``fmukit.entry``).
    API: ClassVar[str]
    STATUS_ERROR: ClassVar[Any]
    STATUS_FATAL: ClassVar[Any]
    RELEASES_ON_EXCEPTION: ClassVar[bool]

    def __init__(self, **kwargs):
        super().__init__(**kwargs)            # pythonfmu's slave, next in the FMU class's MRO
        self.modelName = self.model_name
        self.sequence = CallSequence(self.API)
        self.host_log = self._host_log(kwargs)
        self.failure: str | None = None       # why the FMU failed; until reset
        self.failure_cause = "model"          # its cause (fmukit.refusals.CAUSES)
        self.start_time: float | None = 0.0   # of the experiment, for messages (None: unknown)
        self._step_size = (None, None)        # the last step size given, on the time base
        hostsignals.defer_host_handlers()
        self._model = None
        self._before_variables()
        self.registry = Registry(self, self.variables, self._output)
        self.plans = FastPaths(self, self.registry)
        self._parameters = [v for v in self.variables if v.causality == "parameter"]
        self._check_inputs = range_check(tuple(v for v in self.variables
                                               if v.causality == "input"))

    # -- the adapter's -----------------------------------------------------------
    def _host_log(self, kwargs: dict[str, Any]) -> Any:
        """Where errors reach the user (the adapter's ``hostlog.HostLog``), from pythonfmu's
        keywords: without ``logger`` the host is in this process."""
        raise NotImplementedError

    def fmi_variable(self, var: Var, getter: Callable[[], Any] | None) -> Any:
        """pythonfmu's variable for ``var``; ``getter`` reads an output."""
        raise NotImplementedError

    def _before_variables(self) -> None:
        """What the adapter registers before the declared variables (default: nothing)."""

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
        """An output's value, or NaN (0 if Integer) when it cannot be evaluated or the FMU
        has failed.

        A read never fails: a failed getReal aborts some hosts (libcosim throws
        from a worker thread). Masters read outputs during initialisation, when
        parameters may still be invalid, and feedthrough outputs are evaluated from
        inputs that may be invalid; then the output is undefined, and the call
        that commits (exitInitializationMode, doStep) refuses with a message. A
        master that ignores those statuses still sees NaN outputs. An output that
        its model cannot evaluate from valid inputs while stepping fails the FMU
        (``_unevaluable``).
        """
        if self.failure:
            return undefined
        try:
            if self._model is None:
                self._model = self._started_model()
            return get(self)
        except (ValueError, ArithmeticError) as error:
            if self.sequence.phase == "step":
                self._unevaluable(get, error)
            return undefined

    def _unevaluable(self, get: Callable[[Any], Any], error: Exception) -> None:
        """Fail the FMU, saying where in the model's code, for an output it cannot evaluate
        from valid inputs (a ZeroDivisionError in the user's law): the read gives NaN,
        the next doStep refuses with this reason. With an invalid input, that doStep
        refuses naming the input instead."""
        try:
            self._check_inputs(self)
        except ValueError:
            return
        output = next((f"output {v.name}" for v in self.variables if v.get is get), "an output")
        self.failure = (f"{output} could not be evaluated from valid inputs: "
                        f"{explain(error)}; the FMU has failed")
        self.failure_cause = "model"
        self.log(naming(self.instance_name, self.failure), self.STATUS_ERROR, "fmukit.model")
        self.host_log.tell(self.instance_name, self.failure)

    @property
    def model(self) -> Any:
        """The model; before initialisation, built from the parameters as they are."""
        if self._model is None:
            self._model = self._started_model()
        return self._model

    # -- FMI call sequence -----------------------------------------------------
    @fmi_entry
    def enter_initialization_mode(self) -> None:
        self.sequence.require("EnterInitializationMode", "instantiated")
        self.sequence.phase = "initialization"

    @fmi_entry
    def exit_initialization_mode(self) -> None:
        self.sequence.require("ExitInitializationMode", "initialization")
        self.sequence.phase = "step"
        try:
            for var in self._parameters:      # the declared ranges, then the model's own rules
                var.check(getattr(self, var.name))
            self._model = self._started_model()   # ValueError names a bad parameter or input
        except Exception as error:            # reported now, refused at the first step
            at = "" if self.start_time is None else f" at t = {self.start_time}"
            self.failure = (f"exitInitializationMode{at}: {reason(error)}; the FMU has failed")
            self.failure_cause = _cause(error, "parameter")
            self.log(naming(self.instance_name, self.failure), self.STATUS_ERROR,
                     f"fmukit.{self.failure_cause}")
            self.host_log.tell(self.instance_name, self.failure)

    @fmi_entry
    def terminate(self) -> None:
        if not self.failure:                  # a failed FMU may be terminated in any phase
            self.sequence.require("Terminate", "step")
        self.sequence.phase = "terminated"

    def _step(self, current_time: float, step_size: float) -> None:
        """One communication step (the adapter's ``do_step``); Refused for every refusal."""
        if self.failure:
            raise Refused(self.failure, self.failure_cause)
        refusal = self.sequence.step_refusal()
        if refusal:                           # like any call out of sequence: nothing done
            raise Refused(refusal, "call")
        if not (0.0 < step_size <= MAX_TIME and abs(current_time) <= MAX_TIME):
            self._fail(f"doStep at t = {current_time} with communication step {step_size}: the "
                       f"step must be positive, and both within +-{MAX_TIME:g} s", "step")
        try:
            self._check_inputs(self)
            # The time base of fmukit.timebase: whole nanoseconds, whatever the master. A
            # step under half a nanosecond (the last of a master that adds floats:
            # OMSimulator's 2.8e-13 s at 300 s) is none on that base: nothing changes.
            if step_size != self._step_size[0]:
                self._step_size = (step_size, on_time_base(step_size))
            if self._step_size[1] > 0.0:
                self.step_model(on_time_base(current_time), self._step_size[1])
        except ValueError as error:
            self._fail(f"doStep at t = {current_time}: {error}; the FMU has failed (its "
                       f"outputs read NaN until {self.API}Reset)", _cause(error, "model"))
        except Exception as error:            # the model's own exception
            self._fail(f"doStep at t = {current_time}: {explain(error)}", "model", error)
        except BaseException as error:        # Ctrl-C or the like, raised in this FMU's code
            raise self.interrupted(f"doStep at t = {current_time}", error) from None

    def interrupted(self, where: str, error: BaseException) -> Refused:
        """Fail the FMU for a KeyboardInterrupt (or any BaseException) raised in its code
        while the host called ``where``, and return the refusal to raise. (Rare: the
        host's signal handlers wait until FMU code returns, ``fmukit.hostsignals``.)"""
        number = hostsignals.interrupt_signal(error)
        cause = f"interrupted by {number.name}" if number else explain(error)
        if not self.failure:
            self.failure = f"{where}: {cause}; the FMU has failed"
            self.failure_cause = "interrupted"
        return Refused(self.failure, self.failure_cause)

    def _fail(self, reason: str, cause: str, error: BaseException | None = None) -> NoReturn:
        """Fail the FMU for ``reason`` (its ``cause``): refuse this call and every step until
        reset."""
        self.failure, self.failure_cause = reason, cause
        raise Refused(reason, cause) from error

    # -- setters: refuse what the standard does not allow ----------------------
    def _set(self, vrs: list[int], values: list, convert: type) -> None:
        for vr in vrs:
            self.sequence.check_settable(self.registry.var(vr))
        for vr, value in zip(vrs, values):
            var = self.registry.by_vr[vr]
            if var.kind is not convert:
                raise Refused(f"{var.name} is not of type {convert.__name__}", "call", var.name)
            setattr(self, var.name, convert(value))
            if var.causality == "parameter":
                self._model = None

    def _set_floats(self, vrs: list[int], values: list[float]) -> None:
        """Set Reals (the adapter's setReal or setFloat64)."""
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

    # -- getters ---------------------------------------------------------------------
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


def _cause(error: BaseException, otherwise: str) -> str:
    """A refusal's own cause; ``otherwise`` for any other exception."""
    return error.cause if isinstance(error, Refused) else otherwise
