"""A sweep's spec: the TOML file (``Spec.read``), its controllers and axes, and its runs.

The format is documented in ``cosim.studies.sweep`` and docs/sweeps/example.toml. A
run is one controller at one combination of axis values; its id hashes everything
that determines its result (``Spec.runs``), and ``Spec.job`` is what a worker needs
to run it (``sweep_task``). Combinations that differ only in settings that change
nothing (the wave settings in calm water, ``CALM_WATER_INERT``) have one result, run
once (``Spec.shared_runs``, ``Spec.sharing_notes``). ``Spec.replay`` is the
``cosim.run`` command that reproduces a combination's row bit for bit.

``Spec.read`` refuses, before anything runs or is allocated, what would run something
else than the file says: a parameter set by two axes (or by an axis and a controller's
``set``), a value twice in one axis (as the FMU would receive it: 1 and 1.0 of a Real
are one value), a value its parameter does not take (``cosim.core.values``: NaN,
4294967297 for an Integer, a value outside the declared range; in a spec also a string
for a number), a sweep of more than ``max_runs`` runs, and a name
(of the sweep or a controller) that is not one plain file name, since both name
files in the output folder.
"""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import shlex
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import tomllib

from fmukit.manifest import read as read_manifest

from .. import scenarios
from ..analysis.seastate import model_scale
from ..core.errors import FmuNotFound, FmuUnreadable
from ..core.files import plain_name, read_small_text
from ..core.fmi import read_description
from ..core.inprocess import fallback_note, in_process_refusal
from ..provenance import code_version
from ..core.ssd import SystemDescription
from ..core.values import Declaration, checked, declarations
from ..core.watchdog import Limits
from ..scenarios.autopilot import check_autopilot
from .bundle import Bundle, bundle
from .sweep_task import Job

DEFAULT_CONTROLLERS = {"pd": {"scenario": "waves_pd"}, "smc": {"scenario": "waves_smc"}}
# Axis shorthands: name -> the FMU parameter it sets.
SHORTHANDS = {"wave_seed": "ship.wave_seed", "Hs": "ship.Hs", "T0": "ship.T0",
              "psi_w": "ship.psi_w", "route": "guidance.waypoints"}
SEA_STATE = ("ship.Hs", "ship.T0")
"""What the sea_state axis sets: a WMO code's Hs and T0 at model scale."""

MAX_RUNS = 100_000
"""The most runs a sweep may have unless told otherwise (``cosim.sweep --max-runs``)."""

MAX_SPEC_BYTES = 16 << 20
"""The largest sweep file read (a list of MAX_RUNS values takes about 1 MiB)."""

TOML_TYPES = {"Real": ((int, float), "a number"), "Integer": ((int,), "an integer"),
              "Enumeration": ((int, str), "an integer or an item's name"),
              "Boolean": ((bool,), "true or false"), "String": ((str,), "a string")}
"""The TOML values a parameter of each FMI type takes in a spec: one kind per type, so
that each axis is one column of one type in the tables (no "0.01" beside 0.02)."""

MEASURED = ("guidance.psi_d", "guidance.wp_index", "ship.psi", "ship.delta", "ship.x", "ship.y")
"""The outputs a run's figures of merit and its track are computed from (``sweep_task``)."""

SHIP_SLAVE = "ship_fmu.ship_slave"
"""The module of this project's ship FMU (its manifest's slave module)."""

CALM_WATER_INERT = ("T0", "psi_w", "wave_seed", "wave_components")
"""The ship's parameters that change nothing in calm water (its Hs = 0): the ship makes no
wave loads there (``ship_fmu.vessel.Vessel``), so every signal of a run is the same, bit
for bit, whatever their values (tests/test_sweep_replay.py checks each, in calm_pd,
waves_pd and waves_smc). Held only for a ship FMU built from this checkout's sources."""

REPLAY = ("python", "-m", "cosim.run")
"""The command ``Spec.replay`` reproduces a run with."""


@dataclass
class Spec:
    """A sweep file, read: its controllers (entries of ``controller_entry``), its axes
    (each a list of values) and its [plots]."""
    name: str
    controllers: dict[str, dict[str, Any]]
    axes: dict[str, list]
    stop_time: float | None = None
    map_axes: list[str] = field(default_factory=list)
    tracks: dict[str, Any] | None = None      # which runs record their track: axis values
    _bundles: dict[str, Bundle] | None = field(default=None, repr=False, compare=False)
    _files: dict[str, Path] = field(default_factory=dict, repr=False, compare=False)
    _descriptions: dict[tuple[str, str], Any] = field(default_factory=dict, repr=False,
                                                       compare=False)
    _ships: dict[tuple[str, str], bool] = field(default_factory=dict, repr=False, compare=False)
    _coverage: dict[str, str | None] | None = field(default=None, repr=False, compare=False)

    def wants_track(self, run: dict[str, Any]) -> bool:
        """Whether ``run`` is one of the runs whose tracks are drawn ([plots] tracks)."""
        return self.tracks is not None and all(run.get(k) == v for k, v in self.tracks.items())

    @classmethod
    def read(cls, path: str | Path, max_runs: int = MAX_RUNS) -> Spec:
        """Parse a sweep file; ValueError naming the file, the key and the problem (FmuNotFound
        or FmuUnreadable, naming them too, for a controller whose FMU is missing or broken).
        More than ``max_runs`` runs are refused before any is listed."""
        path = Path(path)
        try:
            data = tomllib.loads(read_small_text(path, MAX_SPEC_BYTES))
        except ValueError as error:                 # TOMLDecodeError too
            raise ValueError(f"cannot read sweep spec {path}: {error}") from None
        unknown = set(data) - {"name", "stop_time", "controllers", "axes", "plots"}
        if unknown:
            raise ValueError(f"{path}: unknown key {', '.join(sorted(unknown))}; a sweep file "
                             "has name, stop_time, [controllers], [axes] and [plots]")
        name = _file_name(path, "name", data.get("name", path.stem))
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
            _file_name(path, f"controller {controller!r}", controller)
        axes = {name: _axis(path, name, values, max_runs)
                for name, values in _typed(path, "[axes]", data.get("axes", {}), dict,
                                           "a table").items()}
        _check_size(path, len(entries), axes, max_runs)
        controllers = {name: controller_entry(entry, path, name)
                       for name, entry in entries.items()}
        _check_overlaps(path, controllers, axes)
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
        spec = cls(name=name, controllers=controllers, axes=axes, stop_time=stop_time,
                   map_axes=map_axes, tracks=tracks)
        spec._check_values(path)
        return spec

    def _check_values(self, path: Path) -> None:
        """Every controller's system has the outputs a run is measured by (``MEASURED``),
        every parameter the axes and the controllers' ``set`` name exists in it and takes
        their values (by FMI type), and no axis repeats a value as the FMU would receive
        it; ValueError naming the file, key and value."""
        try:
            self.bundles()
        except (FmuNotFound, FmuUnreadable) as error:
            raise type(error)(f"{path}: {error}", error.ours) from None
        for controller, shipped in self.bundles().items():
            missing = []
            for target in MEASURED:
                component, _, variable = target.partition(".")
                declared = (self._declared(controller, component)[1].get(variable)
                            if component in shipped.system.components else None)
                if declared is None or declared.causality != "output":
                    missing.append(target)
            if missing:
                raise ValueError(f"{path}: controller {controller!r}: its system "
                                 f"{shipped.system.name!r} has no output {', '.join(missing)}; "
                                 "a run is measured by " + ", ".join(MEASURED) + " (J of eq "
                                 "19 and the track): give a course-keeping scenario")
        declared: dict[tuple[str, str], Declaration] = {}

        def received(controller: str, target: str, value: Any, key: str) -> Any:
            if (controller, target) not in declared:
                declared[controller, target] = self._parameter(controller, target, key, path)
            return _received(declared[controller, target], target, value, path, key)

        for controller in self.controllers:
            for target, value in self.controllers[controller]["set"].items():
                received(controller, target, value, f"controller {controller!r} set {target!r}")
            for axis, values in self.axes.items():
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

    def _parameter(self, controller: str, target: str, key: str, path: Path) -> Declaration:
        """The declaration of parameter ``target`` (component.variable) in a controller's
        system; ValueError if it has no such parameter."""
        system = self.bundles()[controller].system
        component, _, variable = target.partition(".")
        where = f"{path}: {key} sets {target}, but in controller {controller!r}"
        if component not in system.components:
            raise ValueError(f"{where} there is no component {component!r} (there are "
                             f"{', '.join(system.components)})")
        fmu, variables = self._declared(controller, component)
        parameters = [n for n, v in variables.items() if v.causality == "parameter"]
        if variable not in parameters:
            raise ValueError(f"{where} {component} ({fmu.name}) has no parameter "
                             f"{variable!r}; it has {', '.join(parameters)}")
        return variables[variable]

    def _declared(self, controller: str, component: str) -> tuple[Path, dict[str, Declaration]]:
        """A component's FMU in a controller's system, and its variables' declarations."""
        fmu, description = self._description(controller, component)
        return fmu, declarations(description)

    def _description(self, controller: str, component: str) -> tuple[Path, Any]:
        """A component's FMU in a controller's system, and its model description (read once)."""
        if (controller, component) not in self._descriptions:
            source = self.bundles()[controller].system.components[component].source
            fmu = self.files()[Path(source).stem]
            self._descriptions[controller, component] = fmu, read_description(fmu, component)
        return self._descriptions[controller, component]

    def _variable(self, controller: str, target: str):
        """The model variable ``target`` (component.variable) of a controller's system."""
        component, _, name = target.partition(".")
        description = self._description(controller, component)[1]
        return next(v for v in description.modelVariables if v.name == name)

    def bundles(self) -> dict[str, Bundle]:
        """Each controller's system with its FMUs named by content (read once)."""
        if self._bundles is None:
            self._bundles, self._files = {}, {}
            for name, controller in self.controllers.items():
                self._bundles[name], files = bundle(controller)
                self._files.update(files)
        return self._bundles

    def files(self) -> dict[str, Path]:
        """Every FMU the sweep uses, by SHA-256."""
        self.bundles()
        return self._files

    def runs(self) -> list[dict[str, Any]]:
        """Every combination of controller and axis values, with its run id: a hash of
        everything that determines the result (the system and its FMUs' contents, the
        settings, the stop time, the axis values)."""
        names = list(self.axes)
        runs = []
        for controller, shipped in self.bundles().items():
            for values in itertools.product(*(self.axes[n] for n in names)):
                point = {"controller": controller, **dict(zip(names, values))}
                point["run_id"] = _digest({"system": shipped.digest,
                                           "settings": self.settings(point)[1],
                                           "stop_time": self.stop_time, "point": point})
                runs.append(point)
        return runs

    def shared_runs(self) -> list[list[dict[str, Any]]]:
        """The runs (of ``runs``, in its order) grouped by result: a group holds the runs of
        one controller whose settings differ only in what changes nothing (the wave settings
        in calm water, ``CALM_WATER_INERT``). Each group is run once; its result is every
        member's."""
        groups: dict[str, list[dict[str, Any]]] = {}
        for run in self.runs():
            groups.setdefault(self._result_key(run), []).append(run)
        return list(groups.values())

    def _result_key(self, run: dict[str, Any]) -> str:
        """A hash of the controller and the settings of ``run`` that change its result."""
        overrides = self.settings(run)[1]
        inert = self._inert(run["controller"], overrides)
        effective = {component: {variable: value for variable, value in values.items()
                                 if (component, variable) not in inert}
                     for component, values in overrides.items()}
        return _digest({"controller": run["controller"], "settings": effective})

    def _inert(self, controller: str, overrides: dict[str, dict[str, Any]]
               ) -> set[tuple[str, str]]:
        """(component, variable) of every setting that changes nothing in a run of
        ``controller`` with ``overrides``: ``CALM_WATER_INERT`` of each ship in calm water."""
        return {(component, variable) for component in self._calm_ships(controller, overrides)
                for variable in CALM_WATER_INERT}

    def _calm_ships(self, controller: str, overrides: dict[str, dict[str, Any]]) -> list[str]:
        """The components of ``controller``'s system that are this checkout's ship FMU and
        sail in calm water (Hs = 0: set so, else bound so in the system, else by default)."""
        calm = []
        for name, component in self.bundles()[controller].system.components.items():
            if not self._is_our_ship(controller, name):
                continue
            Hs = overrides.get(name, {}).get("Hs", component.parameters.get("Hs"))
            if Hs is None:
                Hs = self._variable(controller, f"{name}.Hs").start
            if float(Hs) == 0.0:
                calm.append(name)
        return calm

    def _is_our_ship(self, controller: str, component: str) -> bool:
        """Whether a component is this project's ship FMU, current here (built from the
        sources whose behaviour ``CALM_WATER_INERT`` states); asked once."""
        if (controller, component) not in self._ships:
            fmu = self._description(controller, component)[0]
            manifest = read_manifest(fmu)
            self._ships[controller, component] = (manifest is not None
                                                  and manifest.slave_module == SHIP_SLAVE
                                                  and in_process_refusal(fmu) is None)
        return self._ships[controller, component]

    def sharing_notes(self) -> list[str]:
        """What ``shared_runs`` saves, in words: 'sea_state 0 is calm water (Hs = 0): the
        wave_seed axis does not apply there; 2 runs instead of 6'."""
        savings: dict[tuple[str, tuple[str, ...]], list[int]] = {}
        for group in self.shared_runs():
            if len(group) > 1:
                varying = tuple(a for a in self.axes
                                if len({json.dumps(r[a]) for r in group}) > 1)
                counts = savings.setdefault((self._calm_because(group[0]), varying), [0, 0])
                counts[0] += 1
                counts[1] += len(group)
        notes = []
        for (why, varying), (runs, combinations) in savings.items():
            axes = (f"the {varying[0]} axis does" if len(varying) == 1 else
                    f"the {', '.join(varying[:-1])} and {varying[-1]} axes do")
            notes.append(f"{why} is calm water (Hs = 0): {axes} not apply there; "
                         f"{runs} run{'s' if runs > 1 else ''} instead of {combinations}")
        return notes

    def _calm_because(self, run: dict[str, Any]) -> str:
        """What makes a run's sea calm, in words: the axis value that sets Hs = 0, else the
        controller's system."""
        controller = run["controller"]
        ships = self._calm_ships(controller, self.settings(run)[1])
        for axis in self.axes:
            if any(f"{ship}.Hs" in assignments(axis, run[axis]) for ship in ships):
                return f"{axis} {run[axis]}"
        return f"controller {controller!r} ({self.bundles()[controller].system.name})"

    def replay(self, run: dict[str, Any]) -> str:
        """The ``cosim.run`` command that reproduces ``run``'s row bit for bit: its scenario
        (and autopilot, with its port map), the stop time and every setting of the run as
        ``--set``, each value as text that reads back as exactly it (a float's repr)."""
        controller = self.controllers[run["controller"]]
        scenario, overrides = self.settings(run)
        words = [*REPLAY, scenario]
        if controller["autopilot"] is not None:
            words += ["--autopilot", controller["autopilot"]]
            for port, renamed in controller["map"].items():
                words += ["--map", f"{port}={renamed}"]
        stop_time = (self.stop_time if self.stop_time is not None
                     else self.bundles()[run["controller"]].system.stop_time)
        words += ["--stop-time", _exact(stop_time)]
        for component, values in overrides.items():
            for variable, value in values.items():
                words += ["--set", f"{component}.{variable}={_exact(value)}"]
        return shlex.join(words)

    def units(self) -> dict[str, str]:
        """Each axis's unit: the one its FMU declares for the parameter it sets ("" for none,
        and for sea_state, whose values are WMO codes)."""
        controller = next(iter(self.controllers))
        units = {}
        for axis, values in self.axes.items():
            targets = list(assignments(axis, values[0]))
            units[axis] = (_declared_unit(self._variable(controller, targets[0]))
                           if len(targets) == 1 else "")
        return units

    def job(self, run: dict[str, Any], sweep: str, backend: str = "fmi",
            limits: Limits = Limits()) -> Job:
        """What a worker needs for ``run`` (of the sweep with token ``sweep``)."""
        return Job(sweep=sweep, run=run, bundle=self.bundles()[run["controller"]],
                   overrides=self.settings(run)[1], stop_time=self.stop_time,
                   track=self.wants_track(run), code=code_version(), backend=backend,
                   limits=limits)

    def backend_notes(self, backend: str) -> list[str]:
        """Which components of which controllers will run through FMI although ``backend``
        is "inprocess" or "batch" (an FMU not of this project, or not built from this
        checkout), and, on "batch", which controllers' runs run alone on the in-process
        route, and why (``batch_coverage``; the FMU it names is not named twice)."""
        if backend not in ("inprocess", "batch"):
            return []
        notes = []
        for controller, shipped in self.bundles().items():
            why = self.batch_coverage()[controller] if backend == "batch" else None
            if why:
                notes.append(f"controller {controller!r} runs on the in-process route, one "
                             f"run per task, not in batches: {why}")
            for name, component in shipped.system.components.items():
                note = fallback_note(name, self.files()[Path(component.source).stem])
                if note and note != why:
                    notes.append(f"controller {controller!r}: {note}")
        return notes

    def batch_coverage(self) -> dict[str, str | None]:
        """Each controller: why the batch kernel cannot run its system
        (``cosim.ensemble.members.coverage``), None if it can (asked once)."""
        if self._coverage is None:
            from ..ensemble.members import coverage

            self._coverage = {controller: coverage(self.local_system(controller))
                              for controller in self.controllers}
        return self._coverage

    def local_system(self, controller: str) -> SystemDescription:
        """A controller's system as its bundle holds it, each FMU the file here."""
        shipped = self.bundles()[controller].system
        return dataclasses.replace(shipped, components={
            name: dataclasses.replace(component,
                                      source=str(self.files()[Path(component.source).stem]))
            for name, component in shipped.components.items()})

    def settings(self, run: dict[str, Any]) -> tuple[str, dict[str, dict[str, Any]]]:
        """(scenario, overrides by component) of one run."""
        controller = self.controllers[run["controller"]]
        overrides: dict[str, dict[str, Any]] = {}

        def put(target: str, value: Any) -> None:
            component, _, variable = target.partition(".")
            overrides.setdefault(component, {})[variable] = value

        for target, value in controller.get("set", {}).items():
            put(target, value)
        for axis in self.axes:
            for target, value in assignments(axis, run[axis]).items():
                put(target, value)
        return controller["scenario"], overrides


def _declared_unit(variable) -> str:
    """The unit a model variable declares, itself or by its type ("" for none)."""
    return variable.unit or (variable.declaredType.unit if variable.declaredType else "") or ""


def _digest(identity: dict[str, Any]) -> str:
    """A short hash of a JSON-able identity."""
    key = json.dumps(identity, sort_keys=True, default=str)
    return hashlib.sha256(key.encode()).hexdigest()[:16]


def _exact(value: Any) -> str:
    """A setting as ``--set`` text that reads back as exactly the value: a float's repr
    (the shortest text of that double), true or false for a Boolean."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else str(value)


def assignments(axis: str, value: Any) -> dict[str, Any]:
    """What one value of an axis sets: component.variable -> value."""
    if axis == "sea_state":
        return dict(zip(SEA_STATE, model_scale(value)))
    return {SHORTHANDS.get(axis, axis): value}


def _typed(path: Path, key: str, value: Any, kind: type, what: str) -> Any:
    if not isinstance(value, kind):
        raise ValueError(f"{path}: {key} = {value!r}: give {what}")
    return value


def _file_name(path: Path, key: str, value: Any) -> str:
    """A name that becomes a file or folder name in the output folder, checked."""
    return plain_name(value, f"{path}: {key}")


def _axis(path: Path, name: str, values: Any, max_runs: int) -> list:
    """An axis's values: a non-empty list, or a range { start = integer, count = integer }
    of at most ``max_runs`` values."""
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
    if name == "sea_state":
        for code in values:
            if isinstance(code, bool) or not isinstance(code, int):
                raise ValueError(f"{path}: axis 'sea_state' has {code!r}: give WMO codes, "
                                 "the integers 0-6")
            try:
                model_scale(code)
            except ValueError as error:
                raise ValueError(f"{path}: axis 'sea_state': {error}") from None
    return values


def _check_size(path: Path, controllers: int, axes: dict[str, list], max_runs: int) -> None:
    """ValueError if the sweep has more than ``max_runs`` runs (counted, not listed)."""
    runs = controllers * math.prod(len(values) for values in axes.values())
    if runs > max_runs:
        factors = " x ".join([f"{controllers} controllers",
                              *(f"{len(v)} {a}" for a, v in axes.items())])
        raise ValueError(f"{path}: {factors} = {runs} runs, more than the {max_runs} a sweep "
                         "may have (cosim.sweep --max-runs)")


def _check_overlaps(path: Path, controllers: dict[str, dict[str, Any]],
                    axes: dict[str, list]) -> None:
    """ValueError if two axes, or an axis and a controller's ``set``, set one parameter:
    the rows would be labelled with values that were not used."""
    setters: dict[str, str] = {}
    for axis, values in axes.items():
        for target in assignments(axis, values[0]):
            if target in setters:
                raise ValueError(f"{path}: axes {setters[target]!r} and {axis!r} both set "
                                 f"{target}; give it one axis")
            setters[target] = axis
    for name, controller in controllers.items():
        for target in controller["set"]:
            if target in setters:
                raise ValueError(f"{path}: controller {name!r} sets {target}, which axis "
                                 f"{setters[target]!r} sets in every run; give it one place")


def _received(declaration: Declaration, target: str, value: Any, path: Path, key: str) -> Any:
    """``value`` exactly as the parameter so declared receives it (``cosim.core.values``);
    ValueError naming the file, the key and the value where it does not take it, or where
    the TOML value is not of the kind its FMI type takes in a spec (``TOML_TYPES``)."""
    kinds, what = TOML_TYPES.get(declaration.type, ((), "nothing"))
    if not isinstance(value, kinds) or isinstance(value, bool) != (bool in kinds):
        raise ValueError(f"{path}: {key} = {value!r}: {target} is an FMI {declaration.type}; "
                         f"give {what}")
    try:
        return checked(target.partition(".")[0], declaration, value)
    except ValueError as error:
        raise ValueError(f"{path}: {key}: {error}") from None


def controller_entry(entry: str | dict[str, Any], spec: Path, name: str) -> dict[str, Any]:
    """A controller entry, checked, with its paths made absolute (relative to the spec file).

    An entry is a scenario (a name or a .ssd path), an autopilot FMU (run in waves_pd's
    place), or a table: scenario, autopilot, map (autopilot port -> the FMU's name), set.
    """
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
