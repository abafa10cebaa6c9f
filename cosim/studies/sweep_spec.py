"""A sweep's spec: its controllers, axes and runs (docs/sweeps.md). A run's id hashes all that
determines its result; combinations that differ only in what changes nothing run once."""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import shlex
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

from fmukit.manifest import read as read_manifest

from .. import scenarios
from ..core.events import check_events
from ..core.system import FmuNotFound, FmuUnreadable
from ..core.fmi import read_description
from ..core.inprocess import fallback_note, in_process_refusal
from ..core.isolation import Isolation
from ..core.ssd import SystemDescription
from ..core.units import unit_of
from ..core.values import Declaration, declarations
from ..core.watchdog import Limits
from ..ensemble.reference import coverage
from ..provenance import code_version
from .spec_file import MAX_RUNS, assignments, check_values, parse
from .sweep_task import Bundle, Job, file_hash

SHIP_SLAVE = "ship_fmu.ship_slave"        # this project's ship FMU (its manifest's module)
# Our ship's parameters that change no bit of a run in calm water (Hs = 0: no wave loads)
CALM_WATER_INERT = ("T0", "psi_w", "wave_seed", "wave_components")


@dataclass
class Spec:
    """A sweep file, read: its controllers (``controller_entry``), axes and [plots]."""
    name: str
    controllers: dict[str, dict[str, Any]]
    axes: dict[str, list]
    stop_time: float | None = None
    map_axes: list[str] = field(default_factory=list)
    tracks: dict[str, Any] | None = None      # which runs record their track: axis values

    @classmethod
    def read(cls, path: str | Path, max_runs: int = MAX_RUNS) -> Spec:
        """A sweep file parsed and checked; ValueError naming the file, key and problem."""
        path = Path(path)
        spec = cls(**parse(path, max_runs))
        try:
            spec.bundles()
        except (FmuNotFound, FmuUnreadable) as error:
            raise type(error)(f"{path}: {error}", error.ours) from None
        check_values(spec, path)
        return spec

    @cached_property
    def _shipped(self) -> dict[str, tuple[Bundle, dict[str, Path], SystemDescription]]:
        return {name: _bundle(controller) for name, controller in self.controllers.items()}

    def bundles(self) -> dict[str, Bundle]:
        """Each controller's system with its FMUs named by content."""
        return {name: shipped[0] for name, shipped in self._shipped.items()}

    def files(self) -> dict[str, Path]:
        """Every FMU the sweep uses, by SHA-256."""
        return {sha: path for _, files, _ in self._shipped.values() for sha, path in files.items()}

    @cached_property
    def fmus(self) -> dict[tuple[str, str], tuple[Path, dict[str, Any], dict[str, Declaration]]]:
        """(controller, component): its FMU, its model variables and their declarations."""
        fmus = {}
        for controller, shipped in self.bundles().items():
            for name, component in shipped.system.components.items():
                fmu = self.files()[Path(component.source).stem]
                description = read_description(fmu, name)
                fmus[controller, name] = (fmu, {v.name: v for v in description.modelVariables},
                                          declarations(description))
        return fmus

    def runs(self) -> list[dict[str, Any]]:
        """Every combination of controller and axis values, with its run id."""
        runs = []
        for controller, shipped in self.bundles().items():
            for values in itertools.product(*self.axes.values()):
                point = {"controller": controller, **dict(zip(self.axes, values))}
                point["run_id"] = _digest({"system": shipped.digest,
                                           "settings": self.settings(point)[1],
                                           "stop_time": self.stop_time, "point": point})[:16]
                runs.append(point)
        return runs

    def shared_runs(self) -> list[list[dict[str, Any]]]:
        """The runs grouped by result: differing only in ``CALM_WATER_INERT`` in calm water."""
        groups: dict[str, list[dict[str, Any]]] = {}
        for run in self.runs():
            calm = self._calm_ships(run)
            effective = {component: {variable: value for variable, value in values.items()
                                     if component not in calm or variable not in CALM_WATER_INERT}
                         for component, values in self.settings(run)[1].items()}
            key = _digest({"controller": run["controller"], "settings": effective})
            groups.setdefault(key, []).append(run)
        return list(groups.values())

    @cached_property
    def _ships(self) -> dict[str, dict[str, Any]]:       # our ship components: the Hs they have
        ships: dict[str, dict[str, Any]] = {controller: {} for controller in self.controllers}
        for (controller, name), (fmu, variables, _) in self.fmus.items():
            manifest = read_manifest(fmu)
            if (manifest is not None and manifest.slave_module == SHIP_SLAVE
                    and in_process_refusal(fmu) is None):
                bound = self.bundles()[controller].system.components[name].parameters
                ships[controller][name] = bound.get("Hs", variables["Hs"].start)
        return ships

    def _calm_ships(self, run: dict[str, Any]) -> list[str]:
        overrides = self.settings(run)[1]
        return [name for name, Hs in self._ships[run["controller"]].items()
                if float(overrides.get(name, {}).get("Hs", Hs)) == 0.0]

    def sharing_notes(self) -> list[str]:
        """What ``shared_runs`` saves, in words."""
        savings: dict[tuple[str, tuple[str, ...]], list[int]] = {}
        for group in self.shared_runs():
            if len(group) > 1:
                varying = tuple(a for a in self.axes if len({json.dumps(r[a]) for r in group}) > 1)
                savings.setdefault((self._calm_because(group[0]), varying), []).append(len(group))
        notes = []
        for (why, varying), sizes in savings.items():
            axes = (f"the {varying[0]} axis does" if len(varying) == 1 else
                    f"the {', '.join(varying[:-1])} and {varying[-1]} axes do")
            notes.append(f"{why} is calm water (Hs = 0): {axes} not apply there; {len(sizes)} "
                         f"run{'s' if len(sizes) > 1 else ''} instead of {sum(sizes)}")
        return notes

    def _calm_because(self, run: dict[str, Any]) -> str:
        for axis in self.axes:
            if any(f"{ship}.Hs" in assignments(axis, run[axis]) for ship in self._calm_ships(run)):
                return f"{axis} {run[axis]}"
        controller = run["controller"]
        return f"controller {controller!r} ({self.bundles()[controller].system.name})"

    def replay(self, run: dict[str, Any]) -> str:
        """The ``cosim.run`` command that reproduces ``run``'s row bit for bit."""
        controller = self.controllers[run["controller"]]
        scenario, overrides = self.settings(run)
        words = ["python", "-m", "cosim.run", scenario]
        if controller["autopilot"] is not None:
            words += ["--autopilot", controller["autopilot"]]
            for port, renamed in controller["map"].items():
                words += ["--map", f"{port}={renamed}"]
        if controller["events"] is not None:
            words += ["--events", controller["events"]]
        stop_time = self.stop_time or self.bundles()[run["controller"]].system.stop_time
        words += ["--stop-time", _exact(stop_time)]
        for component, values in overrides.items():
            for variable, value in values.items():
                words += ["--set", f"{component}.{variable}={_exact(value)}"]
        return shlex.join(words)

    def units(self) -> dict[str, str]:
        """Each axis's unit, as its FMU declares it ("" for none, and for sea_state)."""
        controller = next(iter(self.controllers))
        units = {}
        for axis, values in self.axes.items():
            target, *others = assignments(axis, values[0])
            component, _, name = target.partition(".")
            units[axis] = "" if others else unit_of(self.fmus[controller, component][1][name])
        return units

    def job(self, run: dict[str, Any], sweep: str, backend: str = "fmi",
            limits: Limits = Limits(), isolation: Isolation = Isolation("foreign")) -> Job:
        """What a worker needs for ``run`` of the sweep whose token is ``sweep``."""
        track = self.tracks is not None and all(run.get(k) == v for k, v in self.tracks.items())
        return Job(sweep=sweep, run=run, bundle=self.bundles()[run["controller"]],
                   overrides=self.settings(run)[1], stop_time=self.stop_time, track=track,
                   code=code_version(), backend=backend, limits=limits, isolation=isolation)

    def backend_notes(self, backend: str) -> list[str]:
        """What runs through FMI on "inprocess" or "batch", and alone on "batch", and why."""
        if backend not in ("inprocess", "batch"):
            return []
        notes = []
        for controller, shipped in self.bundles().items():
            why = self.batch_coverage[controller] if backend == "batch" else None
            if why:
                notes.append(f"controller {controller!r} runs on the in-process route, one "
                             f"run per task, not in batches: {why}")
            for name, component in shipped.system.components.items():
                note = fallback_note(name, self.files()[Path(component.source).stem])
                if note and note != why:
                    notes.append(f"controller {controller!r}: {note}")
        return notes

    @cached_property
    def batch_coverage(self) -> dict[str, str | None]:
        """Each controller: why the batch kernel cannot run its system, None if it can."""
        return {name: coverage(system) for name, (_, _, system) in self._shipped.items()}

    def settings(self, run: dict[str, Any]) -> tuple[str, dict[str, dict[str, Any]]]:
        """(scenario, overrides by component) of one run."""
        controller = self.controllers[run["controller"]]
        overrides: dict[str, dict[str, Any]] = {}
        for target, value in [*controller["set"].items(),
                              *(pair for axis in self.axes
                                for pair in assignments(axis, run[axis]).items())]:
            component, _, variable = target.partition(".")
            overrides.setdefault(component, {})[variable] = value
        return controller["scenario"], overrides


def _exact(value: Any) -> str:
    """A setting as ``--set`` text that reads back as exactly the value."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else str(value)


def _bundle(controller: dict[str, Any]) -> tuple[Bundle, dict[str, Path], SystemDescription]:
    """A sweep controller's bundle, its FMUs' files by hash, and its system as loaded here."""
    system = scenarios.load(controller["scenario"], controller["autopilot"], controller["map"])
    if controller["events"] is not None:            # checked against the FMUs here, once
        system = dataclasses.replace(system, events=scenarios.events(controller["events"]))
        check_events(system)
    hashes = {name: file_hash(system.fmu_path(name)) for name in system.components}
    files = {sha: system.fmu_path(name) for name, sha in hashes.items()}
    components = {name: dataclasses.replace(component, source=f"{hashes[name]}.fmu")
                  for name, component in system.components.items()}
    shipped = dataclasses.replace(system, components=components, path=None, fmus=None)
    return Bundle(shipped, _digest(dataclasses.asdict(shipped))), files, system


def _digest(identity: Any) -> str:
    """The SHA-256 of ``identity`` as JSON, keys sorted (what is not JSON: its str)."""
    return hashlib.sha256(json.dumps(identity, sort_keys=True, default=str).encode()).hexdigest()
