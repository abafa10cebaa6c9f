"""The Python entry point: ``simulate`` runs a scenario, with your autopilot if you have one,
``simulate_many`` many runs of one (docs/running.md, "From Python")."""
import dataclasses
import warnings
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from . import scenarios
from .core.isolation import Isolation
from .core.master import BACKENDS, Master
from .core.system import split_name
from .core.recording import Recording, check_signals
from .core.watchdog import STEP_LIMIT_S, Limits, Watchdog


class SimulationError(RuntimeError):
    """An FMU failed during the run; ``recording`` holds the rows up to the failure."""

    def __init__(self, message: str, recording: Recording):
        super().__init__(message)
        self.recording = recording


def parse_setting(text: str) -> tuple[str, str]:
    """'component.variable=value' -> ('component.variable', 'value'), the value as text."""
    target, sep, raw = text.partition("=")
    try:
        split_name(target if sep else "")
    except ValueError:
        raise ValueError(f"--set expects COMPONENT.VARIABLE=VALUE, got {text!r}") from None
    return target, raw


def parse_port_map(text: str) -> tuple[str, str]:
    """'psi=heading' -> ('psi', 'heading'): an autopilot port and the FMU's name for it."""
    port, sep, name = text.partition("=")
    if not (sep and port and name):
        raise ValueError(f"--map expects PORT=NAME, e.g. psi=heading; got {text!r}")
    return port, name


def overrides_of(settings: Mapping[str, Any] | Iterable[tuple[str, Any]]
                 ) -> dict[str, dict[str, Any]]:
    """{'ship.Hs': 0.01} (or pairs) -> {'ship': {'Hs': 0.01}}; ValueError for a bad key or a
    variable given twice."""
    pairs = settings.items() if isinstance(settings, Mapping) else settings
    overrides: dict[str, dict[str, Any]] = {}
    for target, value in pairs:
        try:
            component, variable = split_name(target)
        except ValueError:
            raise ValueError(f"set: {target!r} is not 'component.variable'") from None
        if variable in overrides.get(component, {}):
            raise ValueError(f"set: {target} is given twice ({overrides[component][variable]!r}"
                             f" and {value!r})")
        overrides.setdefault(component, {})[variable] = value
    return overrides


def simulate(scenario: str | Path, autopilot: str | Path | None = None,
             set: dict[str, Any] | None = None, stop_time: float | None = None,
             coupling: str = "gauss-seidel", backend: str = "fmi",
             port_map: dict[str, str] | None = None, fmi: int | None = None,
             isolate: bool | str | Sequence[str] = False, memory_limit: int | None = None,
             step_timeout: float = STEP_LIMIT_S, events: str | Path | None = None) -> Recording:
    """The recording of a scenario (a name or a .ssd path): ``autopilot`` an FMU in its
    autopilot's place, ``set`` values by "component.variable" (SI units), ``events`` timed
    events (a shipped name or an OSP scenario file, as ``cosim.run --events``), ``isolate`` which
    FMUs run in a process of their own (True: all; ``memory_limit`` in bytes; where every FMU
    is, a step past ``step_timeout`` s kills its FMU's process), the rest as ``cosim.run``'s
    options. ValueError for bad input; SimulationError if an FMU fails."""
    system = scenarios.load(scenario, autopilot, port_map, fmi=fmi)
    if events is not None:
        system = dataclasses.replace(system, events=scenarios.events(events))
    with Master(system, coupling=coupling,
                backend=backend, overrides=overrides_of(set or {}),
                isolation=Isolation.of(isolate, memory_limit)) as master:
        for note in master.notes:
            warnings.warn(note, stacklevel=2)
        recording = _run(master, stop_time, step_timeout)
    if recording.error:
        raise SimulationError(recording.error, recording)
    return recording


def _run(master: Master, stop_time: float | None, step_timeout: float) -> Recording:
    """``master.run``; with a step limit where every FMU is isolated (none can hang here)."""
    if not all(kind.endswith("isolated") for kind in master.backends.values()):
        return master.run(stop_time)
    with Watchdog(Limits(step=step_timeout)) as watchdog:
        return master.run(stop_time, watchdog=watchdog)


def simulate_many(scenario: str | Path, sets: Sequence[Mapping[str, Any]],
                  autopilot: str | Path | None = None, stop_time: float | None = None,
                  backend: str = "batch", port_map: dict[str, str] | None = None,
                  fmi: int | None = None, signals: Sequence[str] | None = None,
                  isolate: bool | str | Sequence[str] = False, memory_limit: int | None = None,
                  step_timeout: float = STEP_LIMIT_S) -> list[Recording]:
    """The recordings of a scenario run once for each of ``sets`` (each ``simulate``'s
    ``set``), in order; "batch" steps them together as arrays, holding ``signals`` (``isolate``
    as ``simulate``'s, on the other backends). A failed run raises nothing (its ``error`` says
    why); a refused setting, ValueError naming its member."""
    if backend not in (*BACKENDS, "batch"):
        raise ValueError(f"backend must be fmi, inprocess or batch, got {backend!r}")
    isolation = Isolation.of(isolate, memory_limit)
    if backend == "batch" and isolation.chosen != "none":
        raise ValueError("isolate: the batch route runs no FMU; isolate on the fmi or "
                         "inprocess backend")
    system = scenarios.load(scenario, autopilot, port_map, fmi=fmi)
    overrides = []
    with Master(system, backend="inprocess") as master:     # every member's settings, first
        for i, settings in enumerate(sets):
            try:
                overrides.append(overrides_of(settings))
                master.configure(overrides[-1])
            except ValueError as error:
                raise ValueError(f"member {i}: {error}") from None
        check_signals(signals or (), master.columns)
        recorded = master.columns
    if backend == "batch":
        from .ensemble import simulate_members
        from .ensemble.reference import SIGNALS

        loop = SIGNALS if set(SIGNALS) <= set(recorded) else recorded   # a manoeuvre: all
        recordings = simulate_members(system, overrides, stop_time,
                                      loop if signals is None else signals)
    else:
        recordings = []
        for member in overrides:
            with Master(system, backend=backend, overrides=member,
                        isolation=isolation) as master:
                recording = _run(master, stop_time, step_timeout)
            recordings.append(recording if signals is None else recording.holding(signals))
    for note in dict.fromkeys(n for r in recordings for n in r.meta.get("notes", [])):
        warnings.warn(note, stacklevel=2)
    return recordings
