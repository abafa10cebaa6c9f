"""A sweep's spec: the TOML file (``Spec.read``), its controllers and axes, and its runs.

The format is documented in ``cosim.studies.sweep`` and docs/sweeps/example.toml. A
run is one controller at one combination of axis values; its id hashes everything
that determines its result (``Spec.runs``), and ``Spec.job`` is what a worker needs
to run it (``sweep_task``).
"""
from __future__ import annotations

import hashlib
import itertools
import json
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import scenarios
from ..analysis.seastate import model_scale
from ..core.inprocess import fallback_note
from ..core.provenance import code_version
from ..scenarios.autopilot import check_autopilot
from .bundle import Bundle, bundle
from .sweep_task import Job

DEFAULT_CONTROLLERS = {"pd": {"scenario": "waves_pd"}, "smc": {"scenario": "waves_smc"}}
# Axis shorthands: name -> the FMU parameter it sets.
SHORTHANDS = {"wave_seed": "ship.wave_seed", "Hs": "ship.Hs", "T0": "ship.T0",
              "psi_w": "ship.psi_w", "route": "guidance.waypoints"}


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

    def wants_track(self, run: dict[str, Any]) -> bool:
        """Whether ``run`` is one of the runs whose tracks are drawn ([plots] tracks)."""
        return self.tracks is not None and all(run.get(k) == v for k, v in self.tracks.items())

    @classmethod
    def read(cls, path: str | Path) -> Spec:
        """Parse a sweep file; ValueError naming the file, the key and the problem."""
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError) as error:
            raise ValueError(f"cannot read sweep spec {path}: {error}") from None
        unknown = set(data) - {"name", "stop_time", "controllers", "axes", "plots"}
        if unknown:
            raise ValueError(f"{path}: unknown key {', '.join(sorted(unknown))}; a sweep file "
                             "has name, stop_time, [controllers], [axes] and [plots]")
        name = _typed(path, "name", data.get("name", path.stem), str, "a string")
        stop_time = data.get("stop_time")
        if stop_time is not None and (isinstance(stop_time, bool)
                                      or not isinstance(stop_time, (int, float))
                                      or not stop_time > 0):
            raise ValueError(f"{path}: stop_time = {stop_time!r}: give a number of seconds > 0")
        entries = _typed(path, "[controllers]", data.get("controllers", DEFAULT_CONTROLLERS),
                         dict, "a table")
        controllers = {name: controller_entry(entry, path, name)
                       for name, entry in entries.items()}
        axes = {name: _axis(path, name, values)
                for name, values in _typed(path, "[axes]", data.get("axes", {}), dict,
                                           "a table").items()}
        plots = _typed(path, "[plots]", data.get("plots", {}), dict, "a table")
        map_axes = _typed(path, "[plots] map", plots.get("map", []), list, "a list of axes")
        for axis in map_axes:
            if axis not in axes:
                raise ValueError(f"{path}: [plots] map names {axis!r}, which is not an axis")
        tracks = _typed(path, "[plots] tracks", plots.get("tracks", {}), dict,
                        "a table of axis = value") or None
        for key, value in (tracks or {}).items():
            known = list(controllers) if key == "controller" else axes.get(key)
            if known is None or value not in known:
                raise ValueError(f"{path}: [plots] tracks selects {key} = {value!r}; "
                                 f"select by controller or an axis, with one of its values")
        return cls(name=name, controllers=controllers, axes=axes, stop_time=stop_time,
                   map_axes=map_axes, tracks=tracks)

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
                identity = {"system": shipped.digest, "settings": self.settings(point)[1],
                            "stop_time": self.stop_time, "point": point}
                key = json.dumps(identity, sort_keys=True, default=str)
                point["run_id"] = hashlib.sha256(key.encode()).hexdigest()[:16]
                runs.append(point)
        return runs

    def job(self, run: dict[str, Any], sweep: str, backend: str = "fmi") -> Job:
        """What a worker needs for ``run`` (of the sweep with token ``sweep``)."""
        return Job(sweep=sweep, run=run, bundle=self.bundles()[run["controller"]],
                   overrides=self.settings(run)[1], stop_time=self.stop_time,
                   track=self.wants_track(run), code=code_version(), backend=backend)

    def backend_notes(self, backend: str) -> list[str]:
        """Which components of which controllers will run through FMI although ``backend``
        is "inprocess" (an FMU not of this project, or not built from this checkout)."""
        if backend != "inprocess":
            return []
        notes = []
        for controller, shipped in self.bundles().items():
            for name, component in shipped.system.components.items():
                note = fallback_note(name, self.files()[Path(component.source).stem])
                if note:
                    notes.append(f"controller {controller!r}: {note}")
        return notes

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
            value = run[axis]
            if axis == "sea_state":
                Hs, T0 = model_scale(value)
                put("ship.Hs", Hs)
                put("ship.T0", T0)
            else:
                put(SHORTHANDS.get(axis, axis), value)
        return controller["scenario"], overrides


def _typed(path: Path, key: str, value: Any, kind: type, what: str) -> Any:
    if not isinstance(value, kind):
        raise ValueError(f"{path}: {key} = {value!r}: give {what}")
    return value


def _axis(path: Path, name: str, values: Any) -> list:
    """An axis's values: a non-empty list, or a range { start = integer, count = integer }."""
    if name not in SHORTHANDS and name != "sea_state" and "." not in name:
        raise ValueError(f"{path}: axis {name!r} is neither one of "
                         f"{', '.join(['sea_state', *SHORTHANDS])} nor component.variable")
    if isinstance(values, dict):
        start, count = values.get("start"), values.get("count")
        if set(values) != {"start", "count"} or not all(
                isinstance(v, int) and not isinstance(v, bool) for v in (start, count)) \
                or count < 1:
            raise ValueError(f"{path}: axis {name!r} = {values!r}: a range is "
                             "{ start = <integer>, count = <integer >= 1> }")
        values = list(range(start, start + count))
    if not isinstance(values, list) or not values:
        raise ValueError(f"{path}: axis {name!r} needs a non-empty list of values")
    if name == "sea_state":
        for code in values:
            try:
                model_scale(code)
            except ValueError as error:
                raise ValueError(f"{path}: axis 'sea_state': {error}") from None
    return values


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
