"""A sweep file read and checked: what would run something else than it says is refused before
anything runs, naming the file, the key and the value (docs/sweeps.md)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import tomllib

from .. import scenarios
from ..analysis.seastate import WMO, model_scale
from ..core.files import plain_name, read_small_text
from ..core.values import checked
from ..scenarios.autopilot import check_autopilot

DEFAULT_CONTROLLERS = {"pd": {"scenario": "waves_pd"}, "smc": {"scenario": "waves_smc"}}
SHORTHANDS = {"wave_seed": "ship.wave_seed", "Hs": "ship.Hs", "T0": "ship.T0",
              "psi_w": "ship.psi_w", "route": "guidance.waypoints"}   # axis -> what it sets
SEA_STATE = ("ship.Hs", "ship.T0")      # the sea_state axis: a WMO code's, at model scale
MAX_RUNS = 100_000                      # a sweep's most runs, unless --max-runs says
MEASURED = ("guidance.psi_d", "guidance.wp_index", "ship.psi", "ship.delta", "ship.x", "ship.y")
# The kinds of value a key takes (a bool only where they name bool), what to give, and what
# else it must be: the keys of each table, and the TOML values of each FMI type (one kind per
# type, so that each axis is one column of one type in the tables).
FILE_KEYS = {"name": ((str,), "a plain file name"), "controllers": ((dict,), "a table"),
             "stop_time": ((int, float), "a number of seconds > 0", lambda v: 0 < v < math.inf),
             "axes": ((dict,), "a table"), "plots": ((dict,), "a table"),
             "events": ((str,), "timed events: a name or an OSP scenario file (.json)")}
PLOTS_KEYS = {"map": ((list,), "two different axes", lambda v: not v or (len(v) == 2
                                                                       and v[0] != v[1])),
              "tracks": ((dict,), "a table of axis = value")}
CONTROLLER_KEYS = {"scenario": ((str,), "a string"), "autopilot": ((str,), "a string"),
                   "map": ((dict,), "a table of autopilot port = the FMU's name for it"),
                   "set": ((dict,), "a table of component.variable = value"),
                   "events": ((str,), "timed events: a name or an OSP scenario file (.json)")}
TOML_TYPES = {"Real": ((int, float), "a number"), "Integer": ((int,), "an integer"),
              "Enumeration": ((int, str), "an integer or an item's name"),
              "Boolean": ((bool,), "true or false"), "String": ((str,), "a string")}


def assignments(axis: str, value: Any) -> dict[str, Any]:
    """What one value of an axis sets: component.variable -> value."""
    if axis == "sea_state":
        return dict(zip(SEA_STATE, model_scale(value)))
    return {SHORTHANDS.get(axis, axis): value}


def _given(path: Path, key: str, value: Any, kinds: tuple[type, ...], what: str,
           ok=lambda value: True) -> Any:
    """``value`` if it is of ``kinds`` and ``ok``, else ValueError naming the file, key and it."""
    if not isinstance(value, kinds) or isinstance(value, bool) != (bool in kinds) or not ok(value):
        raise ValueError(f"{path}: {key} = {value!r}: give {what}")
    return value


def _table(path: Path, where: str, table: dict, keys: dict[str, tuple]) -> dict:
    """``table`` (the file's, or ``where``'s), each key known and of its kind (``keys``)."""
    unknown = set(table) - set(keys)
    if unknown:
        raise ValueError(f"{path}: {where or 'the file'} has unknown key "
                         f"{', '.join(sorted(unknown))}; it has {', '.join(keys)}")
    for key, value in table.items():
        _given(path, f"{where} {key}".strip(), value, *keys[key])
    return table


def parse(path: Path, max_runs: int) -> dict[str, Any]:
    """A ``Spec``'s fields from its file, checked but against the FMUs (``check_values``)."""
    try:
        data = tomllib.loads(read_small_text(path, 16 << 20))
    except ValueError as error:                 # TOMLDecodeError too
        raise ValueError(f"cannot read sweep spec {path}: {error}") from None
    except RecursionError:
        raise ValueError(f"cannot read sweep spec {path}: its tables or arrays are nested "
                         "too deeply") from None
    _table(path, "", data, FILE_KEYS)
    name = plain_name(data.get("name", path.stem), f"{path}: name")
    entries = data.get("controllers", DEFAULT_CONTROLLERS)
    if not entries:
        raise ValueError(f"{path}: [controllers] is empty; name at least one controller")
    for controller in entries:
        plain_name(controller, f"{path}: controller {controller!r}")
    axes = {a: _axis(path, a, values, max_runs) for a, values in data.get("axes", {}).items()}
    runs = len(entries) * math.prod(len(values) for values in axes.values())
    if runs > max_runs:
        factors = " x ".join([f"{len(entries)} controllers",
                              *(f"{len(v)} {a}" for a, v in axes.items())])
        raise ValueError(f"{path}: {factors} = {runs} runs, more than the {max_runs} a sweep "
                         "may have (cosim.sweep --max-runs)")
    controllers = {c: controller_entry(entry, path, c, data.get("events"))
                   for c, entry in entries.items()}
    setters: dict[str, str] = {}                # no parameter set in two places
    for who, targets in [*((f"axis {a!r}", assignments(a, v[0])) for a, v in axes.items()),
                         *((f"controller {c!r}", e["set"]) for c, e in controllers.items())]:
        for target in targets:
            if target in setters:
                raise ValueError(f"{path}: {setters[target]} and {who} both set {target}; "
                                 "give it one place")
        if who.startswith("axis"):
            setters.update(dict.fromkeys(targets, who))
    plots = _table(path, "[plots]", data.get("plots", {}), PLOTS_KEYS)
    map_axes = plots.get("map", [])
    for axis in map_axes:
        if not isinstance(axis, str) or axis not in axes:
            raise ValueError(f"{path}: [plots] map names {axis!r}, which is not an axis")
    tracks = plots.get("tracks") or None
    for key, value in (tracks or {}).items():
        known = list(controllers) if key == "controller" else axes.get(key, [])
        if not any(value == v and type(value) is type(v) for v in known):
            raise ValueError(f"{path}: [plots] tracks selects {key} = {value!r}; "
                             f"select by controller or an axis, with one of its values")
    return {"name": name, "controllers": controllers, "axes": axes,
            "stop_time": data.get("stop_time"), "map_axes": map_axes, "tracks": tracks}


def check_values(spec, path: Path) -> None:
    """Each system has ``MEASURED``; each parameter set exists, takes its values, none twice."""
    for controller, shipped in spec.bundles().items():
        missing = [target for target in MEASURED
                   if getattr(_declared(spec, controller, target), "causality", "") != "output"]
        if missing:
            raise ValueError(f"{path}: controller {controller!r}: its system "
                             f"{shipped.system.name!r} has no output {', '.join(missing)}; "
                             "a run is measured by " + ", ".join(MEASURED) + " (J of eq "
                             "19 and the track): give a course-keeping scenario")
    for controller, entry in spec.controllers.items():
        for target, value in entry["set"].items():
            _received(spec, path, controller, target, value,
                      f"controller {controller!r} set {target!r}")
        for axis, values in spec.axes.items():
            seen: dict[tuple, Any] = {}
            for value in values:
                exact = tuple(_received(spec, path, controller, target, v, f"axis {axis!r}")
                              for target, v in assignments(axis, value).items())
                if exact in seen:
                    same = (f"{value!r} twice" if repr(seen[exact]) == repr(value) else
                            f"{seen[exact]!r} and {value!r}, one value for the FMU")
                    raise ValueError(f"{path}: axis {axis!r} has {same}: each of its runs "
                                     "would be run twice; give each value once")
                seen[exact] = value


def _declared(spec, controller: str, target: str):
    component, _, variable = target.partition(".")
    return spec.fmus.get((controller, component), (None, {}, {}))[2].get(variable)


def _received(spec, path: Path, controller: str, target: str, value: Any, key: str) -> Any:
    component, _, variable = target.partition(".")
    fmu, _, variables = spec.fmus.get((controller, component), (None, {}, {}))
    declaration = variables.get(variable)
    if getattr(declaration, "causality", "") != "parameter":
        where = f"{path}: {key} sets {target}, but in controller {controller!r}"
        if fmu is None:
            raise ValueError(f"{where} there is no component {component!r} (there are "
                             f"{', '.join(spec.bundles()[controller].system.components)})")
        raise ValueError(f"{where} {component} ({fmu.name}) has no parameter {variable!r}; "
                         "it has " + ", ".join(n for n, v in variables.items()
                                               if v.causality == "parameter"))
    kinds, what = TOML_TYPES.get(declaration.type, ((), "nothing"))
    _given(path, key, value, kinds, f"{what} ({target} is an FMI {declaration.type})")
    try:
        return checked(component, declaration, value)
    except ValueError as error:
        raise ValueError(f"{path}: {key}: {error}") from None


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
        if set(values) != {"start", "count"} or any(type(v) is not int for v in (start, count)) \
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
        if isinstance(code, bool) or not isinstance(code, int) or code not in WMO:
            raise ValueError(f"{path}: axis 'sea_state' has {code!r}: give WMO codes, "
                             "the integers 0-6")
    return values


def controller_entry(entry: str | dict[str, Any], spec: Path, name: str,
                     events: str | None = None) -> dict[str, Any]:
    """A controller entry checked, its paths made absolute (relative to the spec file);
    ``events``: the sweep's timed events, for a controller that names none."""
    if isinstance(entry, str):
        entry = {"autopilot": entry} if entry.endswith(".fmu") else {"scenario": entry}
    where = f"controller {name!r}"
    _given(spec, where, entry, (dict,), "a scenario, an autopilot FMU, or a table of scenario, "
                                        "autopilot, map and set")
    _table(spec, where, entry, CONTROLLER_KEYS)
    for port, renamed in entry.get("map", {}).items():
        _given(spec, f"{where} map {port!r}", renamed, (str,), "the FMU's name of the port")
    for target, value in entry.get("set", {}).items():
        if "." not in target or isinstance(value, dict):
            raise ValueError(f"{spec}: {where} set {target!r} = {value!r}: give "
                             "component.variable = value, the key quoted (\"autopilot.Kp\" = 2.0)")

    def beside_spec(value: str) -> str:
        return str((spec.parent / value).resolve()) if value.endswith((".ssd", ".fmu")) \
            else value
    events = entry.get("events", events)
    scenario = beside_spec(entry.get("scenario", "waves_pd" if "autopilot" in entry else ""))
    autopilot = entry.get("autopilot")
    try:
        scenarios.path(scenario)
        if autopilot is not None:
            autopilot = beside_spec(autopilot)
            check_autopilot(autopilot, entry.get("map"), trial=True)
            scenarios.load(scenario, autopilot, entry.get("map"))
        if events is not None:
            if events.endswith(".json"):            # else a name of the shipped ones
                events = str((spec.parent / events).resolve())
            scenarios.events(events)
    except (ValueError, FileNotFoundError) as error:
        raise ValueError(f"{spec}: {where}: {error}") from None
    return {"scenario": scenario, "autopilot": autopilot, "map": dict(entry.get("map", {})),
            "set": dict(entry.get("set", {})), "events": events}
