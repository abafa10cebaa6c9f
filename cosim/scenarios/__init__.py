"""The scenarios, one SSP system structure file (.ssd) each, by name (``calm_pd``) or path;
``PAPER``: the four behind Tables 1-2; ``autopilot`` puts a user's FMU into one; timed
events (OSP scenario files) shipped by name in events/."""
from __future__ import annotations

from pathlib import Path

from fmubuild import project

from ..core.events import Event, EventsError, read_events
from ..core.files import plain_name
from ..core.ssd import read_ssd
from ..core.system import (FmuFolders, SystemDescription, close_matches, did_you_mean,
                           with_fmi)
from .autopilot import with_autopilot

SCENARIO_DIR = Path(__file__).resolve().parent
PAPER = ("calm_pd", "calm_smc", "waves_pd", "waves_smc")    # Tomera (2010), Tables 1-2


def names() -> list[str]:
    return sorted(p.stem for p in SCENARIO_DIR.glob("*.ssd"))


def path(scenario: str | Path) -> Path:
    """A scenario's .ssd by name or path; ValueError listing the names, FileNotFoundError."""
    if str(scenario).endswith(".ssd"):
        if not Path(scenario).is_file():
            raise FileNotFoundError(f"no system structure file {scenario}")
        return Path(scenario)
    if scenario not in names():
        raise ValueError(f"unknown scenario {scenario!r}; valid scenarios: {', '.join(names())}"
                         + did_you_mean(close_matches(str(scenario), names())))
    return SCENARIO_DIR / f"{scenario}.ssd"


def events(name: str | Path) -> tuple[Event, ...]:
    """Timed events: shipped by name (cosim/scenarios/events/NAME.json: ``event_names``) or
    from an OSP scenario file; EventsError naming the file or listing the names."""
    if str(name).isidentifier():
        if name not in event_names():
            raise EventsError(f"unknown events {name!r}; shipped: {', '.join(event_names())}, "
                              "or give an OSP scenario file (.json)")
        name = SCENARIO_DIR / "events" / f"{name}.json"
    return tuple(read_events(name))


def event_names() -> list[str]:
    return sorted(p.stem for p in (SCENARIO_DIR / "events").glob("*.json"))


def label(scenario: str | Path, autopilot: str | Path | None = None,
          name: str | None = None) -> str:
    """A run's name in file names: the scenario's, then the autopilot's if not its own."""
    if name is not None:
        plain_name(name, "the autopilot's name")
    stem = Path(scenario).stem
    made = f"{stem}-{name or Path(autopilot).stem}" if autopilot is not None else stem
    return plain_name(made, f"the run's name from {Path(scenario).name}"
                            f"{'' if autopilot is None else f' and {Path(autopilot).name}'}"
                            " (rename the file)")


def load(scenario: str | Path, autopilot: str | Path | None = None,
         port_map: dict[str, str] | None = None, name: str | None = None,
         fmi: int | None = None) -> SystemDescription:
    """A scenario's system, this project's FMUs of FMI version ``fmi`` and ``autopilot`` in."""
    system = read_ssd(path(scenario), FmuFolders(dict(project.FMU_DIRS),
                                                 frozenset({*project.FMUS, *project.C_FMUS})))
    if fmi is not None:
        system = with_fmi(system, fmi)
    return system if autopilot is None else with_autopilot(system, autopilot, port_map, name)
