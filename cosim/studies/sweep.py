"""Ensembles of co-simulations on Dask: Monte Carlo over seeds, sea states and settings.

    python -m cosim.sweep docs/sweeps/smc_vs_pd.toml             # local cluster, 1 worker/core
    python -m cosim.sweep SPEC --scheduler tcp://host:8786       # an existing Dask cluster
    python -m cosim.sweep SPEC --workers 2 --csv --out results/sweeps

SPEC is a TOML file (see docs/sweeps/example.toml):

    name = "example"                       # output folder results/sweeps/<name>/
    stop_time = 400                        # s, optional (default: the scenario's)

    [controllers]                          # the controller axis: base scenario and settings
    pd = { scenario = "waves_pd" }
    smc = { scenario = "waves_smc", set = { "autopilot.eta_h" = 10.0 } }
    mine = { autopilot = "my.fmu", map = { psi = "heading" } }   # your own, in waves_pd
    other = "path/to/other.ssd"            # or a scenario, or an autopilot FMU, alone

    [axes]                                 # every combination is run
    wave_seed = { start = 1, count = 20 }  # or a list
    sea_state = [0, 2, 3]                  # WMO codes -> Hs, T0 at 1:70 (cosim.analysis.seastate)
    Hs = [0.005]                           # m (instead of sea_state); T0 likewise
    psi_w = [3.14159]                      # rad, wave direction
    route = ["0,0;30,0;60,25;90,25"]       # guidance waypoints
    "ship.delta_rate_max" = [0.0873, 0.349] # any FMU parameter, component.variable

    [plots]
    map = ["sea_state", "ship.delta_rate_max"]   # axes of the J_SMC / J_PD map
    tracks = { sea_state = 3 }             # overlay the tracks of these runs (all seeds)

Without [controllers], pd and smc run on waves_pd and waves_smc. Paths are relative
to the sweep file; an autopilot FMU must keep the port contract of
``cosim.scenarios.autopilot``.

Each Dask task is one whole co-simulation with our master. A worker extracts the
FMUs once per scenario and thread and resets them (fmi2Reset) between tasks.
Results: results/sweeps/<name>/runs.jsonl gets each row as it completes (flushed),
so an interrupted sweep resumes where it stopped; results.parquet (and
results.csv with --csv) hold the table at the end; a summary is printed, two
figures are written, and comparison.md pairs every controller with pd seed by seed. A task whose worker dies is retried twice, then recorded
as failed; an FMU error is recorded as failed at once, with its message.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import sys
import threading
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from distributed import WorkerPlugin

from .. import scenarios
from ..analysis.cost import cost
from ..analysis.metrics import sign_reversals_per_minute
from ..analysis.seastate import model_scale
from ..scenarios.autopilot import check_autopilot
from .cluster import connect

DEFAULT_CONTROLLERS = {"pd": {"scenario": "waves_pd"}, "smc": {"scenario": "waves_smc"}}
# Axis shorthands: name -> the FMU parameter it sets.
SHORTHANDS = {"wave_seed": "ship.wave_seed", "Hs": "ship.Hs", "T0": "ship.T0",
              "psi_w": "ship.psi_w", "route": "guidance.waypoints"}
METRICS = {"psi_E": "rad^2", "sum_delta2": "rad^2", "J": "rad^2",
           "rms_heading_error_deg": "deg", "reversals_per_min": "1/min", "max_delta_deg": "deg"}
"""The figures of merit of a run and their units, as ``cosim.run`` prints them."""


@dataclass
class Spec:
    name: str
    controllers: dict[str, dict[str, Any]]
    axes: dict[str, list]
    stop_time: float | None = None
    map_axes: list[str] = field(default_factory=list)
    tracks: dict[str, Any] | None = None      # which runs record their track: axis values

    def wants_track(self, run: dict[str, Any]) -> bool:
        """Whether ``run`` is one of the runs whose tracks are drawn ([plots] tracks)."""
        return self.tracks is not None and all(run.get(k) == v for k, v in self.tracks.items())

    @classmethod
    def read(cls, path: str | Path) -> Spec:
        """Parse a sweep file; ValueError naming the file and the problem."""
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError) as error:
            raise ValueError(f"cannot read sweep spec {path}: {error}") from None
        controllers = {name: controller_entry(entry, path, name)
                       for name, entry in data.get("controllers", DEFAULT_CONTROLLERS).items()}
        axes = {}
        for name, values in data.get("axes", {}).items():
            if isinstance(values, dict):
                values = list(range(values["start"], values["start"] + values["count"]))
            if not isinstance(values, list) or not values:
                raise ValueError(f"{path}: axis {name!r} needs a non-empty list of values")
            if name not in SHORTHANDS and name != "sea_state" and "." not in name:
                raise ValueError(f"{path}: axis {name!r} is neither one of "
                                 f"{', '.join(['sea_state', *SHORTHANDS])} nor component.variable")
            if name == "sea_state":
                for code in values:
                    model_scale(code)            # ValueError for codes outside 0-6
            axes[name] = values
        plots = data.get("plots", {})
        map_axes = plots.get("map", [])
        for axis in map_axes:
            if axis not in axes:
                raise ValueError(f"{path}: [plots] map names {axis!r}, which is not an axis")
        tracks = plots.get("tracks")
        for key, value in (tracks or {}).items():
            known = list(controllers) if key == "controller" else axes.get(key)
            if known is None or value not in known:
                raise ValueError(f"{path}: [plots] tracks selects {key} = {value!r}; "
                                 f"select by controller or an axis, with one of its values")
        return cls(name=data.get("name", path.stem), controllers=controllers, axes=axes,
                   stop_time=data.get("stop_time"), map_axes=map_axes, tracks=tracks)

    def runs(self) -> list[dict[str, Any]]:
        """Every combination of controller and axis values, with a stable run id."""
        names = list(self.axes)
        runs = []
        for controller in self.controllers:
            for values in itertools.product(*(self.axes[n] for n in names)):
                point = {"controller": controller, **dict(zip(names, values))}
                key = json.dumps(point, sort_keys=True)
                point["run_id"] = hashlib.sha1(key.encode()).hexdigest()[:12]
                runs.append(point)
        return runs

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


def controller_entry(entry: str | dict[str, Any], spec: Path, name: str) -> dict[str, Any]:
    """A controller entry, checked, with its paths made absolute (relative to the spec file).

    An entry is a scenario (a name or a .ssd path), an autopilot FMU (run in waves_pd's
    place), or a table: scenario, autopilot, map (autopilot port -> the FMU's name), set.
    """
    if isinstance(entry, str):
        entry = {"autopilot": entry} if entry.endswith(".fmu") else {"scenario": entry}
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


# -- the task, on a worker ------------------------------------------------------------
_masters: dict[tuple[int, str], Any] = {}       # (thread, controller) -> Master
_masters_lock = threading.Lock()


def _key(controller: dict[str, Any]) -> tuple[int, str]:
    system = {k: controller[k] for k in ("scenario", "autopilot", "map")}
    return threading.get_ident(), json.dumps(system, sort_keys=True)


def _master(controller: dict[str, Any]):
    from ..core.master import Master

    key = _key(controller)
    with _masters_lock:
        master = _masters.get(key)
    if master is None:
        master = Master(scenarios.load(controller["scenario"], controller["autopilot"],
                                       controller["map"]))
        with _masters_lock:
            _masters[key] = master
    else:
        master.reset()
    return master


def _drop_master(controller: dict[str, Any]) -> None:
    with _masters_lock:
        master = _masters.pop(_key(controller), None)
    if master is not None:
        master.free()


def free_masters() -> None:
    """Free every cached master of this process (worker teardown)."""
    with _masters_lock:
        masters = list(_masters.values())
        _masters.clear()
    for master in masters:
        master.free()


def _row(run: dict[str, Any], error: str = "") -> dict[str, Any]:
    """A result row for ``run``: failed with ``error`` if given, metrics still undefined."""
    return {**run, "status": "failed" if error else "ok", "error": error,
            **{m: math.nan for m in METRICS}, "seconds": math.nan}


def run_one(spec: Spec, run: dict[str, Any]) -> dict[str, Any]:
    """One whole co-simulation; never raises for a failed run, records it."""
    started = time.perf_counter()
    row = _row(run)
    controller = spec.controllers[run["controller"]]
    try:
        _, overrides = spec.settings(run)
        master = _master(controller)
        master.configure(overrides)
        recording = master.run(spec.stop_time)
    except Exception as error:              # a bad setting: not worth retrying
        _drop_master(controller)
        row = _row(run, f"{type(error).__name__}: {error}")
    else:
        if recording.error:
            _drop_master(controller)        # its FMUs may be in an error state
            row = _row(run, recording.error)
        else:
            row.update(_metrics(recording))
            if spec.wants_track(run):
                row["track"] = _track(recording, master.parameters)
    row["seconds"] = time.perf_counter() - started
    return row


def _track(recording, parameters: dict[str, dict[str, Any]], every: float = 1.0) -> dict:
    """The run's track every ``every`` s, and its route, for the tracks figure."""
    stride = max(1, round(every / recording.meta["step_size"]))
    return {"x": recording["ship.x"][::stride].tolist(),
            "y": recording["ship.y"][::stride].tolist(),
            "route": parameters.get("guidance", {}).get("waypoints")}


def _metrics(recording) -> dict[str, float]:
    c = cost(recording)
    delta = recording["ship.delta"]
    return {"psi_E": c.psi_E, "sum_delta2": c.sum_delta2, "J": c.J,
            "rms_heading_error_deg": math.degrees(math.sqrt(c.psi_E / recording.rows)),
            "reversals_per_min": sign_reversals_per_minute(recording.t, delta),
            "max_delta_deg": math.degrees(float(np.abs(delta).max()))}


# -- the client side --------------------------------------------------------------------
class Journal:
    """Rows appended and flushed as they complete: a sweep resumes from it."""

    def __init__(self, path: Path):
        self.path = path
        self.rows: dict[str, dict] = {}
        if path.exists():
            for line in path.read_text().splitlines():
                if line.strip():
                    row = json.loads(line)
                    self.rows[row["run_id"]] = row

    def add(self, row: dict) -> None:
        with open(self.path, "a") as f:
            f.write(json.dumps(row) + "\n")
            f.flush()
        self.rows[row["run_id"]] = row


class _Teardown(WorkerPlugin):
    """Free a worker's cached FMUs (and their temporary folders) at shutdown."""

    name = "cosim-sweep-teardown"

    def teardown(self, worker) -> None:
        free_masters()


def execute(spec: Spec, out: Path, scheduler: str | None = None, workers: int | None = None,
            progress: bool = True, task=None) -> list[dict]:
    """Run the runs not yet in the journal; return every row of the sweep.

    ``task(spec, run) -> row`` is what each run executes (default ``run_one``). On
    Ctrl-C or SIGTERM (``Interrupted``, raised again once the cluster is closed) the
    runs completed so far stay in the journal (``completed``) and runs in progress
    are lost; the same call then resumes.
    """
    from dask.distributed import as_completed

    journal = Journal(out / "runs.jsonl")
    todo = [r for r in spec.runs() if r["run_id"] not in journal.rows]
    if todo:
        client, cluster = connect(scheduler, workers)
        try:
            client.register_plugin(_Teardown())
            futures = {client.submit(task or run_one, spec, run, retries=2, pure=False,
                                     key=f"run-{run['run_id']}"): run for run in todo}
            bar = None
            if progress:
                from tqdm import tqdm
                bar = tqdm(total=len(todo), desc=spec.name, unit="run", file=sys.stderr,
                           disable=None)                # None: only on a terminal
            for future in as_completed(futures):
                try:
                    row = future.result()
                except Exception as error:          # the worker died on every retry
                    row = _row(futures[future], f"{type(error).__name__}: {error}")
                journal.add(row)
                if bar is not None:
                    bar.update()
            if bar is not None:
                bar.close()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    return completed(spec, out)


def completed(spec: Spec, out: Path) -> list[dict]:
    """The rows of ``spec``'s runs in its journal, in the order of ``spec.runs()``."""
    rows = Journal(out / "runs.jsonl").rows
    return [rows[r["run_id"]] for r in spec.runs() if r["run_id"] in rows]


def write_tables(rows: list[dict], out: Path, csv: bool) -> list[Path]:
    """results.parquet (each metric's unit in its field metadata), results.csv with ``csv``,
    and results.json: the unit of every column."""
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    table = pa.Table.from_pylist([{k: (json.dumps(v) if isinstance(v, (list, dict)) else v)
                                   for k, v in row.items() if k != "track"} for row in rows])
    units = {name: METRICS.get(name, "s" if name == "seconds" else "")
             for name in table.column_names}
    table = table.cast(pa.schema([field.with_metadata({"unit": units[field.name]})
                                  for field in table.schema]))
    written = [out / "results.parquet", out / "results.json"]
    pq.write_table(table, written[0])
    written[1].write_text(json.dumps({"units": units}, indent=1) + "\n")
    if csv:
        written.append(out / "results.csv")
        pacsv.write_csv(table, written[2])
    return written


def summary(spec: Spec, rows: list[dict]) -> str:
    ok = [r for r in rows if r["status"] == "ok"]
    lines = [f"{spec.name}: {len(rows)} runs, {len(ok)} ok, {len(rows) - len(ok)} failed"]
    for controller in spec.controllers:
        J = np.array([r["J"] for r in ok if r["controller"] == controller])
        if J.size:
            lines.append(f"  {controller:>14}: J median {np.median(J):9.2f}, mean {J.mean():9.2f}"
                         f", 5-95 % {np.percentile(J, 5):9.2f} - {np.percentile(J, 95):9.2f}"
                         f" ({J.size} runs)")
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"  failed {r['run_id']} {r['controller']}: "
                         f"{r['error'].splitlines()[0][:160]}")
            break
    return "\n".join(lines)


def comparison(spec: Spec, rows: list[dict], baseline: str = "pd",
               monte_carlo: str = "wave_seed") -> str:
    """Markdown table: per setting of the other axes, median J and wins against the baseline.

    Runs are paired by the Monte Carlo axis (the same sea for both controllers); a
    controller wins a pair when its J is lower. The share of wins and the median J
    ratio are given for every controller other than the baseline.
    """
    others = [c for c in spec.controllers if c != baseline]
    axes = [a for a in spec.axes if a != monte_carlo]
    ok = {(r["controller"], *(json.dumps(r[a]) for a in spec.axes)): r
          for r in rows if r["status"] == "ok"}
    header = [*axes, f"J {baseline}", *(f"J {c}" for c in others),
              *(f"{c} wins" for c in others), *(f"J {c} / J {baseline}" for c in others)]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for setting in itertools.product(*(spec.axes[a] for a in axes)):
        where = dict(zip(axes, setting))
        seeds = spec.axes.get(monte_carlo, [None])

        def J(controller: str) -> np.ndarray:
            keys = [(controller, *(json.dumps(where.get(a, seed)) for a in spec.axes))
                    for seed in seeds]
            return np.array([ok[k]["J"] if k in ok else np.nan for k in keys])

        def median(values: np.ndarray) -> str:
            return f"{np.nanmedian(values):.1f}" if np.isfinite(values).any() else "-"

        base = J(baseline)
        cells = [str(v) for v in setting] + [median(base)]
        wins, ratios = [], []
        for controller in others:
            J_c = J(controller)
            cells.append(median(J_c))
            decided = np.isfinite(J_c) & np.isfinite(base) & (J_c != base)
            wins.append(f"{int(np.sum(J_c[decided] < base[decided]))}/{int(decided.sum())}")
            defined = np.isfinite(J_c) & (base > 1e-9)
            ratios.append(f"{np.median(J_c[defined] / base[defined]):.2f}" if defined.any()
                          else "-")
        lines.append("| " + " | ".join(cells + wins + ratios) + " |")
    return "\n".join(lines)
