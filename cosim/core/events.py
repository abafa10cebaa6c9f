"""Timed events in OSP's scenario format (libcosim's JSON: ``events``, each a ``time``,
``model``, ``variable``, ``action`` and ``value``, with ``defaults`` and ``end``), applied as
libcosim applies them: at the first communication point at or after the event's time, before
that step. ``override`` holds a value (on a connected input, in place of what the connection
sends), ``bias`` adds one to the variable's own value, ``reset`` ends either. Events set inputs
and tunable parameters: FMI fixes every other parameter once initialised."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fmukit.timebase import nanoseconds

from .fmi import read_description
from .system import SystemDescription
from .values import Declaration, checked, declarations, no_variable

ACTIONS = ("override", "bias", "reset")
_KEYS = {"time", "model", "variable", "action", "value"}


class EventsError(ValueError):
    """A scenario file that cannot be read, or whose events do not fit the system."""


@dataclass(frozen=True)
class Event:
    time: float                 # s after the run's start
    model: str                  # the component
    variable: str
    action: str
    value: Any = None           # none for reset


def read_events(path: str | Path) -> list[Event]:
    """The events of an OSP scenario file, in time order; EventsError naming the file and the
    event that is wrong."""
    where = f"scenario file {path}"
    if Path(path).suffix.lower() in (".yml", ".yaml"):
        raise EventsError(f"{where}: this reads OSP's JSON form only; write the same keys "
                          "in a .json file")
    try:
        document = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise EventsError(f"{where} cannot be read: {error}") from None
    if not (isinstance(document, dict) and isinstance(document.get("events"), list)
            and isinstance(document.get("defaults", {}), dict)):
        raise EventsError(f"{where}: OSP's scenario format is an object with a list "
                          "'events' and, optionally, an object 'defaults'")
    end = document.get("end", math.inf)
    if "end" in document and not _is_time(end):
        raise EventsError(f"{where}: 'end' = {end!r} is not a time in seconds >= 0")
    events = []
    for i, item in enumerate(document["events"]):
        event = {**document.get("defaults", {}), **item} if isinstance(item, dict) else None
        problem = (
            "is not an object" if event is None else
            f"has unknown keys {sorted(set(event) - _KEYS)}" if set(event) - _KEYS else
            f"'time' = {event.get('time')!r} is not a time in seconds from 0 to the end, "
            f"{end:g}" if not (_is_time(event.get("time")) and event["time"] <= end) else
            "needs 'model' and 'variable' (text), here or in 'defaults'"
            if not all(isinstance(event.get(k), str) for k in ("model", "variable")) else
            f"'action' = {event.get('action')!r} is not one of {', '.join(ACTIONS)}"
            if event.get("action") not in ACTIONS else
            "needs a 'value' (reset takes none)"
            if (event["action"] == "reset") == ("value" in event) else None)
        if problem:
            raise EventsError(f"{where}: event {i} {problem}")
        events.append(Event(float(event["time"]), event["model"], event["variable"],
                            event["action"], event.get("value")))
    return sorted(events, key=lambda e: e.time)


def _is_time(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and 0 <= value < math.inf


class Schedule:
    """A run's events by the step they come before, checked against the FMUs' declarations
    (EventsError naming the event); ``apply`` carries out a step's."""

    def __init__(self, events: list[Event], declarations: dict[str, dict[str, Declaration]],
                 paths: dict[str, Path], h: float):
        self.due: dict[int, list[tuple[Event, Any]]] = {}
        for event in events:
            declared = declarations.get(event.model)
            d = None if declared is None else declared.get(event.variable)
            name = f"{event.model}.{event.variable}"
            why = (f"no component {event.model!r} (the system has {', '.join(declarations)})"
                   if declared is None else
                   str(no_variable(event.model, paths[event.model], declared, event.variable))
                   if d is None else
                   f"{name} is a {d.variability} {d.causality}; events set inputs and tunable "
                   "parameters" if d.causality != "input" and d.variability != "tunable" else
                   f"bias adds to a Real; {name} is {d.type}"
                   if event.action == "bias" and d.type != "Real" else None)
            try:
                if why:
                    raise ValueError(why)
                value = None if event.value is None else checked(event.model, d, event.value)
            except ValueError as error:
                raise EventsError(f"event at {event.time:g} s: {error}") from None
            k = -(-nanoseconds(event.time) // nanoseconds(h))     # the first t_k >= its time
            self.due.setdefault(k, []).append((event, value))
        self.own: dict[tuple[str, str], Any] = {}      # a variable's value before any event

    def apply(self, k: int, t: float, instances: dict[str, Any], nodes: dict[str, Any]) -> None:
        """Carry out the events due before step ``k`` (at ``t``)."""
        for event, value in self.due.get(k, ()):
            node, name = nodes[event.model], f"{event.model}.{event.variable}"
            if name in node.input_names:                # what the connection sends, modified
                i = node.input_names.index(name)
                node.modifiers.pop(i, None)
                if event.action != "reset":
                    node.modifiers[i] = ((lambda s, v=value: v) if event.action == "override"
                                         else (lambda s, v=value: s + v))
                continue
            instance, key = instances[event.model], (event.model, event.variable)
            own = self.own.setdefault(key, instance.get([event.variable])[event.variable])
            new = {"override": value, "reset": own}.get(event.action, own + (value or 0.0))
            slave = getattr(instance, "slave", None)    # FMI 3.0 tunes in configuration mode
            configure = getattr(instance, "fmi_version", 2) == 3 and hasattr(
                slave, "enterConfigurationMode") and \
                instance.variables[event.variable].causality == "parameter"
            if configure:
                instance.call("enterConfigurationMode", slave.enterConfigurationMode, time=t)
            instance.set({event.variable: new}, time=t)
            if configure:
                instance.call("exitConfigurationMode", slave.exitConfigurationMode, time=t)


def check_events(system: SystemDescription) -> None:
    """EventsError if ``system``'s events do not fit its FMUs, as a master would say."""
    paths = {name: system.fmu_path(name) for name in system.components}
    Schedule(system.events, {name: declarations(read_description(path, name, system.ours(path)))
                             for name, path in paths.items()}, paths, system.steps()[1])
