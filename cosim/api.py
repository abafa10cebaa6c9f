"""The Python entry point: one call runs a scenario, with your autopilot if you have one.

    from cosim import simulate
    run = simulate("waves_pd", autopilot="my.fmu", set={"ship.Hs": 0.01}, stop_time=200)
    run["ship.psi"], run.t, run.units["ship.psi"]        # heading (rad) at every 0.1 s

The recording holds every exchanged signal by ``component.variable`` (every FMU
output and every connected input) at every communication point, and the unit of
each. ``cosim.testing`` turns this into pytest checks.
"""
from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, Iterable, Mapping

from . import scenarios
from .core.master import Master
from .core.ssd import split_name
from .core.recording import Recording


class SimulationError(RuntimeError):
    """An FMU failed during the run; ``recording`` holds the rows up to the failure."""

    def __init__(self, message: str, recording: Recording):
        super().__init__(message)
        self.recording = recording


def parse_setting(text: str) -> tuple[str, str]:
    """'component.variable=value' -> ('component.variable', 'value'). The value stays text:
    the master reads it as the type the FMU declares for the variable, once, and refuses
    what that type cannot hold exactly (``cosim.core.values``). ValueError naming the
    text if it is not of that form."""
    target, sep, raw = text.partition("=")
    try:
        if not sep:
            raise ValueError("no '='")
        split_name(target)
    except ValueError:
        raise ValueError(f"--set expects COMPONENT.VARIABLE=VALUE, got {text!r}") from None
    return target, raw


def overrides_of(settings: Mapping[str, Any] | Iterable[tuple[str, Any]]
                 ) -> dict[str, dict[str, Any]]:
    """{'ship.Hs': 0.01} (or pairs, as ``parse_setting`` gives them) -> {'ship': {'Hs':
    0.01}}; ValueError for a key that is not 'component.variable' or a variable given
    twice."""
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
             port_map: dict[str, str] | None = None, fmi: int | None = None) -> Recording:
    """Run a scenario (a name or a .ssd path) and return its recording.

    ``autopilot``: an FMU in place of the scenario's (``cosim.scenarios.autopilot``),
    its ports renamed by ``port_map``; ``set``: parameter values by
    ``"component.variable"`` (SI units, radians); ``stop_time`` in s (default: the
    scenario's). ``fmi=3`` runs this project's FMI 3.0 twins (fmus/fmi3/) in place of the
    FMUs the scenario names (``fmi=2``: fmus/), with the same results bit for bit; an
    ``autopilot`` may be of either version. ``backend="inprocess"`` runs this project's
    FMUs as Python classes, without FMI: the same results bit for bit, about 1.5-2.5
    times faster (an FMU not built from this checkout's classes runs through FMI, with a
    warning). ValueError or FileNotFoundError for bad input, naming it; SimulationError if
    an FMU fails during the run.
    """
    with Master(scenarios.load(scenario, autopilot, port_map, fmi=fmi), coupling=coupling,
                backend=backend, overrides=overrides_of(set or {})) as master:
        for note in master.notes:
            warnings.warn(note, stacklevel=2)
        recording = master.run(stop_time)
    if recording.error:
        raise SimulationError(recording.error, recording)
    return recording
