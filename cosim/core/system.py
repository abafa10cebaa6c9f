"""A system: its components, their connections and experiment, and where its FMUs are (the
core's model of a flat co-simulation; ``ssd`` reads and writes it as SSP 1.0); the errors of
an FMU file, and the advice a message ends with ("did you mean")."""
from __future__ import annotations

import copy
import difflib
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

from fmukit.timebase import nanoseconds, seconds, step_count

COMPONENT_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,99}")
PORT_NAME = re.compile(r"(?!\s)[^,\"\x00-\x1f\x7f]{1,200}(?<!\s)")


class _FmuFileError(Exception):
    """``ours``: the file is named as one of the FMUs the caller builds (a command may say how)."""

    def __init__(self, message: str, ours: bool):
        super().__init__(message)
        self.ours = ours


class FmuNotFound(_FmuFileError, FileNotFoundError):
    """No FMU file where a component's source says."""


class FmuUnreadable(_FmuFileError, ValueError):
    """A file that is not a readable FMU."""


def close_matches(name: str, names: Iterable[str]) -> list[str]:
    """The names a user who typed ``name`` likely meant, best first: equal but for case, then
    up to three alike (difflib's ratio 0.7: 'ship' for 'shp', not 'wave_seed' for 'wave_height')."""
    names = list(dict.fromkeys(names))
    folded = {n.lower(): n for n in reversed(names)}            # the first of each
    close = [folded[n] for n in difflib.get_close_matches(name.lower(), list(folded), 3, 0.7)]
    same = [n for n in names if n.lower() == name.lower()]
    return list(dict.fromkeys(n for n in [*same, *close] if n != name))


def did_you_mean(matches: list[str]) -> str:
    """"; did you mean 'Hs'?" for ``matches``; '' for none."""
    if not matches:
        return ""
    *rest, last = [f"'{n}'" for n in matches]
    return f"; did you mean {', '.join(rest) + ' or ' if rest else ''}{last}?"


def split_name(name: str) -> tuple[str, str]:
    """'ship.psi' -> ('ship', 'psi'); ValueError naming ``name`` if it is not so."""
    component, dot, variable = name.partition(".") if isinstance(name, str) else ("", "", "")
    if not (dot and component and variable):
        raise ValueError(f"{name!r} is not 'component.variable'")
    return component, variable


@dataclass(frozen=True)
class FmuFolders:
    """Where the caller builds its FMUs (a folder per FMI version) and their names (stems)."""
    by_fmi: dict[int, Path]
    names: frozenset[str]

    def fmi_of(self, path: Path) -> int | None:
        """The FMI version of the folder ``path`` is in, if it is one of these FMUs."""
        if path.stem not in self.names:
            return None
        return next((fmi for fmi, folder in self.by_fmi.items() if path.parent == folder), None)


@dataclass
class Component:
    name: str
    source: str                                  # FMU path, relative to the .ssd
    connectors: dict[str, tuple[str, str]] = field(default_factory=dict)   # name: (kind, type)
    parameters: dict[str, float | int | bool | str] = field(default_factory=dict)


@dataclass(frozen=True)
class Connection:
    start_element: str
    start_connector: str
    end_element: str
    end_connector: str

    def __str__(self) -> str:
        return (f"{self.start_element}.{self.start_connector} -> "
                f"{self.end_element}.{self.end_connector}")


@dataclass
class SystemDescription:
    name: str
    components: dict[str, Component]
    connections: list[Connection]
    start_time: float = 0.0
    stop_time: float = 400.0
    step_size: float = 0.1
    report: str = "none"
    description: str = ""
    path: Path | None = None                     # the .ssd this was read from
    events: tuple = ()                           # timed events (``core.events.Event``)
    fmus: FmuFolders | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        """ValueError for a name no file format takes as it is: a component's becomes a CSV
        column's prefix, a JSON key, a file name and an OMSimulator identifier."""
        for name, component in self.components.items():
            if not COMPONENT_NAME.fullmatch(name):
                raise ValueError(f"component name {name!r}: a component is named with ASCII "
                                 "letters, digits and _, not starting with a digit, as every "
                                 "engine and file the name reaches takes it")
            for port in component.connectors:
                if not PORT_NAME.fullmatch(port):
                    raise ValueError(f"{name}.{port}: a connector's name holds no comma, "
                                     "quote, space at either end or control character (it "
                                     "heads a CSV column)")

    def parameters(self, overrides: dict[str, dict[str, Any]] | None = None
                   ) -> dict[str, dict[str, Any]]:
        """Each component's parameter values updated by ``overrides``; ValueError if unknown."""
        parameters = {name: dict(c.parameters) for name, c in self.components.items()}
        for component, values in (overrides or {}).items():
            if component not in parameters:
                raise ValueError(f"--set names the component '{component}'; the system has "
                                 f"{', '.join(parameters)}"
                                 f"{did_you_mean(close_matches(component, parameters))}")
            parameters[component].update(values)
        return parameters

    def steps(self, stop_time: float | None = None) -> tuple[float, float, int]:
        """(t0, h on the time base, whole steps) to ``stop_time`` (default: the system's)."""
        h = seconds(nanoseconds(self.step_size))
        return self.start_time, h, step_count(
            self.start_time, self.stop_time if stop_time is None else stop_time, h)

    def ours(self, path: str | Path) -> bool:           # named as one of the FMUs of ``fmus``
        return self.fmus is not None and Path(path).stem in self.fmus.names

    def fmu_candidates(self, component: str) -> list[Path]:
        """Where a component's FMU may be: its source relative to the .ssd (or the current
        folder), then unless absolute (another file would run unseen), in the first folder of
        ``fmus`` by its path after that folder's name (``../fmi3/ship.fmu``: ``fmi3/ship.fmu``)."""
        source = Path(self.components[component].source)
        candidates = [((self.path.parent if self.path else Path.cwd()) / source).resolve()]
        if self.fmus is not None and not source.is_absolute():
            root, parts = next(iter(self.fmus.by_fmi.values())), source.parts[:-1]
            after = len(parts) - parts[::-1].index(root.name) if root.name in parts else -1
            candidates.append(root.joinpath(*source.parts[after:]))
        return list(dict.fromkeys(candidates))

    def fmu_path(self, component: str) -> Path:
        """The first of ``fmu_candidates`` that exists; FmuNotFound naming all tried."""
        candidates = self.fmu_candidates(component)
        for path in candidates:
            if path.is_file():
                return path
        ours = self.ours(self.components[component].source)
        twin = ours and 3 in map(self.fmus.fmi_of, candidates)
        hint = (f"one of this project's {'FMI 3.0 ' if twin else ''}FMUs, not built" if ours
                else f"check the source of component '{component}' in {self.path or 'the system'}")
        raise FmuNotFound(f"FMU for '{component}' not found; tried "
                          f"{', '.join(map(str, candidates))}; {hint}", ours)


def with_fmi(system: SystemDescription, fmi: int) -> SystemDescription:
    """A copy of ``system`` whose components that run FMUs of ``system.fmus`` (found in, or
    missing from, one of its folders) take those of FMI version ``fmi``."""
    folders = system.fmus.by_fmi if system.fmus else {}
    if fmi not in folders:
        raise ValueError(f"FMI {fmi}: this project's FMUs are built for FMI "
                         f"{' and '.join(f'{v}.0' for v in folders) or 'no version'}")
    new = copy.deepcopy(system)
    for name, component in new.components.items():
        candidates = system.fmu_candidates(name)
        found = next((p for p in candidates if p.is_file()), None)
        if any(system.fmus.fmi_of(p) for p in ([found] if found else candidates)):
            component.source = str(folders[fmi] / Path(component.source).name)
    return new
