"""What the master needs of a component, whichever backend runs it (``Instance``), and the
errors and log records of its FMI calls."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Iterable, NamedTuple

from .units import unit_of
from .values import fmi_value, no_variable

class LogRecord(NamedTuple):
    """One message an FMU logged."""
    status: str                 # ok, warning, discard, error, fatal, pending
    category: str | None
    text: str

    def __str__(self) -> str:
        return f"[{self.status}] {self.text}"

    @property
    def cause(self) -> str | None:
        """What an FMU built with fmukit refused (category fmukit.<cause>); None otherwise."""
        fmukit = (self.category or "").startswith("fmukit.")
        return self.category.removeprefix("fmukit.") if fmukit else None


class FmuCallError(RuntimeError):
    """An FMI call returned discard, error or fatal: the FMU's log and its refusal's cause."""

    def __init__(self, instance: str, call: str, time: float | None, status: str,
                 records: Iterable[LogRecord]):
        self.instance, self.call, self.time, self.status = instance, call, time, status
        self.records = list(records)
        self.messages = [str(r) for r in self.records]
        self.cause = next((r.cause for r in self.records if r.cause), None)
        at = "" if time is None else f" at t = {time:.6g} s"
        # an FMU built with fmukit names itself in its messages; any other's are labelled
        log = "".join(f"\n  {r}" if r.cause else f"\n  {instance} log: {r}"
                      for r in self.records)
        super().__init__(f"FMU '{instance}': {call}{at} returned {status}{log}")


def logged_error(records: Iterable[LogRecord]) -> bool:
    return any(r.status in ("error", "fatal") for r in records)


class Instance:
    """One instantiated component: a backend supplies ``call(what, function, *args, time,
    strict)`` (FmuCallError if it fails or, ``strict``, logs an error), ``fmi(name)``, ``reset``,
    ``enter_initialization``, ``free`` and ``stepper``; ``__new__`` names it for a watchdog."""

    name: str
    path: Path
    guid: str | None
    variables: dict[str, Any]          # name: object with valueReference, type, causality
    feedthrough: dict[str, frozenset[str]]   # output name: the inputs it depends on

    def __new__(cls, path: str | Path = "", name: str = "", *args: Any, **kwargs: Any):
        instance = super().__new__(cls)
        instance.path, instance.name = Path(path), name
        return instance

    def variable(self, name: str):
        """The model variable, or ValueError listing the valid names."""
        try:
            return self.variables[name]
        except KeyError:
            raise no_variable(self.name, self.path, self.variables, name) from None

    def vr(self, name: str) -> int:
        return self.variable(name).valueReference

    def unit(self, name: str) -> str:
        """The unit a variable declares (its own or its type's), "" if none."""
        return unit_of(self.variable(name))

    def set(self, values: dict[str, Any], time: float | None = None) -> None:
        """Set variables by name; ValueError for a value the call cannot carry exactly."""
        for name, value in values.items():
            kind = self._kind(name)
            exact = fmi_value(f"{self.name}.{name}", kind, value)
            self.call(f"set {name} = {exact!r}", self.fmi(f"set{kind}"), [self.vr(name)],
                      [exact], time=time)

    def get(self, names: Iterable[str]) -> dict[str, Any]:
        """Current values of variables by name, one FMI call per type."""
        names, values = list(names), {}
        for kind in dict.fromkeys(self._kind(name) for name in names):
            group = [name for name in names if self._kind(name) == kind]
            read = self.call(f"get {', '.join(group)}", self.fmi(f"get{kind}"),
                             [self.vr(name) for name in group])
            values.update((n, v.decode("utf-8") if isinstance(v, bytes) else v)
                          for n, v in zip(group, read))
        return {name: values[name] for name in names}

    def _kind(self, name: str) -> str:              # fmi2SetInteger sets an Enumeration
        kind = self.variable(name).type
        return "Integer" if kind == "Enumeration" else kind

    def parameter_values(self) -> dict[str, Any]:
        """Every parameter's value as the FMU holds it."""
        return self.get([n for n, v in self.variables.items() if v.causality == "parameter"])

    def initialize(self, parameters: dict[str, Any] | None = None,
                   start_time: float = 0.0) -> None:
        self.enter_initialization(start_time)
        self.set(parameters or {}, time=start_time)
        self.exit_initialization(start_time)

    def exit_initialization(self, start_time: float = 0.0) -> None:
        """Strict: our FMUs log invalid parameters here (``fmukit.slave``)."""
        self.call("exitInitializationMode", self.fmi("exitInitializationMode"), time=start_time,
                  strict=True)

    def do_step(self, t: float, h: float) -> None:
        self.stepper()(t, h)

    # Prepared calls for a fixed list of value references, valid until ``reset``.
    def reader(self, vrs: list[int], kind: str = "Real") -> Callable[[], list]:
        return lambda: self.call(f"get{kind}", self.fmi(f"get{kind}"), vrs)

    def writer(self, vrs: list[int]) -> Callable[[list[float]], None]:
        return lambda values: self.call("setReal", self.fmi("setReal"), vrs, values)
