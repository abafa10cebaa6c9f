"""A sweep file read and checked (docs/sweeps.md): what would run something else than it says
is refused before anything runs, naming the file, the key and the value."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import tomllib

from .. import scenarios
from ..analysis.seastate import model_scale
from ..core.files import plain_name, read_small_text
from ..core.values import Declaration, checked
from ..scenarios.autopilot import check_autopilot

DEFAULT_CONTROLLERS = {"pd": {"scenario": "waves_pd"}, "smc": {"scenario": "waves_smc"}}
SHORTHANDS = {"wave_seed": "ship.wave_seed", "Hs": "ship.Hs", "T0": "ship.T0",
              "psi_w": "ship.psi_w", "route": "guidance.waypoints"}
"""Axis shorthands: name -> the FMU parameter it sets."""
SEA_STATE = ("ship.Hs", "ship.T0")
"""What the sea_state axis sets: a WMO code's Hs and T0 at model scale."""
MAX_RUNS = 100_000
"""The most runs a sweep may have unless told otherwise (``cosim.sweep --max-runs``)."""
TOML_TYPES = {"Real": ((int, float), "a number"), "Integer": ((int,), "an integer"),
              "Enumeration": ((int, str), "an integer or an item's name"),
              "Boolean": ((bool,), "true or false"), "String": ((str,), "a string")}
"""The TOML values a parameter of each FMI type takes: one kind per type, so that each axis
is one column of one type in the tables."""
MEASURED = ("guidance.psi_d", "guidance.wp_index", "ship.psi", "ship.delta", "ship.x", "ship.y")
"""The outputs a run's figures of merit and its track are computed from."""


def assignments(axis: str, value: Any) -> dict[str, Any]:
    """What one value of an axis sets: component.variable -> value."""
    if axis == "sea_state":
        return dict(zip(SEA_STATE, model_scale(value)))
    return {SHORTHANDS.get(axis, axis): value}


def parse(path: Path, max_runs: int) -> dict[str, Any]:
    """The fields of a ``Spec`` from its file, each checked but against the FMUs
    (``check_values``); more than ``max_runs`` runs are refused before any is listed."""
    try:
        data = tomllib.loads(read_small_text(path, 16 << 20))
    except ValueError as error:                 # TOMLDecodeError too
        raise ValueError(f"cannot read sweep spec {path}: {error}") from None
    unknown = set(data) - {"name", "stop_time", "controllers", "axes", "plots"}
    if unknown:
        raise ValueError(f"{path}: unknown key {', '.join(sorted(unknown))}; a sweep file "
                         "has name, stop_time, [controllers], [axes] and [plots]")
    name = plain_name(data.get("name", path.stem), f"{path}: name")
    stop_time = data.get("stop_time")
    if stop_time is not None and (isinstance(stop_time, bool)
                                  or not isinstance(stop_time, (int, float))
                                  or not 0 < stop_time < math.inf):
        raise ValueError(f"{path}: stop_time = {stop_time!r}: give a number of seconds > 0")
    entries = _typed(path, "[controllers]", data.get("controllers", DEFAULT_CONTROLLERS),
                     dict, "a table")
    if not entries:
        raise ValueError(f"{path}: [controllers] is empty; name at least one controller")
    for controller in entries:
        plain_name(controller, f"{path}: controller {controller!r}")
    axes = {name: _axis(path, name, values, max_runs)
            for name, values in _typed(path, "[axes]", data.get("axes", {}), dict,
                                       "a table").items()}
    runs = len(entries) * math.prod(len(values) for values in axes.values())
    if runs > max_runs:
        factors = " x ".join([f"{len(entries)} controllers",
                              *(f"{len(v)} {a}" for a, v in axes.items())])
        raise ValueError(f"{path}: {factors} = {runs} runs, more than the {max_runs} a sweep "
                         "may have (cosim.sweep --max-runs)")
    controllers = {name: controller_entry(entry, path, name) for name, entry in entries.items()}
    setters: dict[str, str] = {}                # no parameter set in two places
    for axis, values in axes.items():
        for target in assignments(axis, values[0]):
            if target in setters:
                raise ValueError(f"{path}: axes {setters[target]!r} and {axis!r} both set "
                                 f"{target}; give it one axis")
            setters[target] = axis
    for controller, entry in controllers.items():
        for target in entry["set"]:
            if target in setters:
                raise ValueError(f"{path}: controller {controller!r} sets {target}, which axis "
                                 f"{setters[target]!r} sets in every run; give it one place")
    plots = _typed(path, "[plots]", data.get("plots", {}), dict, "a table")
    unknown = set(plots) - {"map", "tracks"}
    if unknown:
        raise ValueError(f"{path}: [plots] has {', '.join(sorted(unknown))}; it has map "
                         "and tracks")
    map_axes = _typed(path, "[plots] map", plots.get("map", []), list, "a list of axes")
    if map_axes and (len(map_axes) != 2 or map_axes[0] == map_axes[1]):
        raise ValueError(f"{path}: [plots] map = {map_axes!r}: give two different axes")
    for axis in map_axes:
        if not isinstance(axis, str) or axis not in axes:
            raise ValueError(f"{path}: [plots] map names {axis!r}, which is not an axis")
    tracks = _typed(path, "[plots] tracks", plots.get("tracks", {}), dict,
                    "a table of axis = value") or None
    for key, value in (tracks or {}).items():
        known = list(controllers) if key == "controller" else axes.get(key, [])
        if not any(value == v and type(value) is type(v) for v in known):
            raise ValueError(f"{path}: [plots] tracks selects {key} = {value!r}; "
                             f"select by controller or an axis, with one of its values")
    return {"name": name, "controllers": controllers, "axes": axes, "stop_time": stop_time,
            "map_axes": map_axes, "tracks": tracks}


def check_values(spec, path: Path) -> None:
    """Every controller's system has the outputs of ``MEASURED``, every parameter the axes and
    the controllers' ``set`` name exists and takes their values, and no axis repeats a value
    as the FMU would receive it (1 and 1.0 of a Real are one)."""
    for controller, shipped in spec.bundles().items():
        missing = []
        for target in MEASURED:
            component, _, variable = target.partition(".")
            found = (spec.declared(controller, component)[1].get(variable)
                     if component in shipped.system.components else None)
            if found is None or found.causality != "output":
                missing.append(target)
        if missing:
            raise ValueError(f"{path}: controller {controller!r}: its system "
                             f"{shipped.system.name!r} has no output {', '.join(missing)}; "
                             "a run is measured by " + ", ".join(MEASURED) + " (J of eq "
                             "19 and the track): give a course-keeping scenario")
    declared: dict[tuple[str, str], Declaration] = {}

    def received(controller: str, target: str, value: Any, key: str) -> Any:
        """``value`` exactly as the parameter receives it (``cosim.core.values``); ValueError
        where the system has no such parameter, it does not take the value, or the TOML
        value is not of its type's kind (``TOML_TYPES``)."""
        component, _, variable = target.partition(".")
        if (controller, target) not in declared:
            system = spec.bundles()[controller].system
            where = f"{path}: {key} sets {target}, but in controller {controller!r}"
            if component not in system.components:
                raise ValueError(f"{where} there is no component {component!r} (there are "
                                 f"{', '.join(system.components)})")
            fmu, variables = spec.declared(controller, component)
            parameters = [n for n, v in variables.items() if v.causality == "parameter"]
            if variable not in parameters:
                raise ValueError(f"{where} {component} ({fmu.name}) has no parameter "
                                 f"{variable!r}; it has {', '.join(parameters)}")
            declared[controller, target] = variables[variable]
        declaration = declared[controller, target]
        kinds, what = TOML_TYPES.get(declaration.type, ((), "nothing"))
        if not isinstance(value, kinds) or isinstance(value, bool) != (bool in kinds):
            raise ValueError(f"{path}: {key} = {value!r}: {target} is an FMI "
                             f"{declaration.type}; give {what}")
        try:
            return checked(component, declaration, value)
        except ValueError as error:
            raise ValueError(f"{path}: {key}: {error}") from None

    for controller in spec.controllers:
        for target, value in spec.controllers[controller]["set"].items():
            received(controller, target, value, f"controller {controller!r} set {target!r}")
        for axis, values in spec.axes.items():
            seen: dict[tuple, Any] = {}
            for value in values:
                exact = tuple(received(controller, target, v, f"axis {axis!r}")
                              for target, v in assignments(axis, value).items())
                if exact in seen:
                    same = (f"{value!r} twice" if repr(seen[exact]) == repr(value) else
                            f"{seen[exact]!r} and {value!r}, one value for the FMU")
                    raise ValueError(f"{path}: axis {axis!r} has {same}: each of its runs "
                                     "would be run twice; give each value once")
                seen[exact] = value


def _typed(path: Path, key: str, value: Any, kind: type, what: str) -> Any:
    if not isinstance(value, kind):
        raise ValueError(f"{path}: {key} = {value!r}: give {what}")
    return value


def _axis(path: Path, name: str, values: Any, max_runs: int) -> list:
    """An axis's values: a non-empty list, or { start = integer, count = integer }."""
    if name not in SHORTHANDS and name != "sea_state" and "." not in name:
        hint = (f"; for component.variable, quote the key: \"{name}.{next(iter(values))}\" = "
                "[...]" if isinstance(values, dict) and values
                and set(values) != {"start", "count"} else "")
        raise ValueError(f"{path}: axis {name!r} is neither one of "
                         f"{', '.join(['sea_state', *SHORTHANDS])} nor component.variable{hint}")
    if isinstance(values, dict):
        start, count = values.get("start"), values.get("count")
        if set(values) != {"start", "count"} or not all(
                isinstance(v, int) and not isinstance(v, bool) for v in (start, count)) \
                or count < 1:
            raise ValueError(f"{path}: axis {name!r} = {values!r}: a range is "
                             "{ start = <integer>, count = <integer >= 1> }")
        if count > max_runs:
            raise ValueError(f"{path}: axis {name!r} = {values!r}: {count} values, more than "
                             f"the {max_runs} runs a sweep may have (cosim.sweep --max-runs)")
        values = list(range(start, start + count))
    if not isinstance(values, list) or not values:
        raise ValueError(f"{path}: axis {name!r} needs a non-empty list of values")
    for code in values if name == "sea_state" else ():
        if isinstance(code, bool) or not isinstance(code, int):
            raise ValueError(f"{path}: axis 'sea_state' has {code!r}: give WMO codes, "
                             "the integers 0-6")
        try:
            model_scale(code)
        except ValueError as error:
            raise ValueError(f"{path}: axis 'sea_state': {error}") from None
    return values


def controller_entry(entry: str | dict[str, Any], spec: Path, name: str) -> dict[str, Any]:
    """A controller entry checked, its paths made absolute (relative to the spec file): a
    scenario (a name or a .ssd path), an autopilot FMU (in waves_pd), or a table of
    scenario, autopilot, map (autopilot port -> the FMU's name) and set."""
    if isinstance(entry, str):
        entry = {"autopilot": entry} if entry.endswith(".fmu") else {"scenario": entry}
    if not isinstance(entry, dict):
        raise ValueError(f"{spec}: controller {name!r} = {entry!r}: give a scenario, an "
                         "autopilot FMU, or a table of scenario, autopilot, map and set")
    unknown = set(entry) - {"scenario", "autopilot", "map", "set"}
    if unknown:
        raise ValueError(f"{spec}: controller {name!r} has {', '.join(sorted(unknown))}; a "
                         "controller has scenario, autopilot, map and set")
    for key in ("scenario", "autopilot"):
        _typed(spec, f"controller {name!r} {key}", entry.get(key, ""), str, "a string")
    ports = _typed(spec, f"controller {name!r} map", entry.get("map", {}), dict,
                   "a table of autopilot port = the FMU's name for it")
    for port, renamed in ports.items():
        _typed(spec, f"controller {name!r} map {port!r}", renamed, str,
               "the FMU's name of the port")
    settings = _typed(spec, f"controller {name!r} set", entry.get("set", {}), dict,
                      "a table of component.variable = value")
    for target, value in settings.items():
        if "." not in target or isinstance(value, dict):
            raise ValueError(f"{spec}: controller {name!r} set {target!r} = {value!r}: give "
                             "component.variable = value, the key quoted (\"autopilot.Kp\" = 2.0)")

    def beside_spec(value: str) -> str:
        return str((spec.parent / value).resolve()) if value.endswith((".ssd", ".fmu")) \
            else value
    scenario = beside_spec(entry.get("scenario", "waves_pd" if "autopilot" in entry else ""))
    try:
        scenarios.path(scenario)
        autopilot = entry.get("autopilot")
        if autopilot is not None:
            autopilot = beside_spec(autopilot)
            check_autopilot(autopilot, entry.get("map"), trial=True)
            scenarios.load(scenario, autopilot, entry.get("map"))
    except (ValueError, FileNotFoundError) as error:
        raise ValueError(f"{spec}: controller {name!r}: {error}") from None
    return {"scenario": scenario, "autopilot": autopilot, "map": dict(entry.get("map", {})),
            "set": dict(entry.get("set", {}))}
