"""Ensembles of co-simulations on Dask: Monte Carlo over seeds, sea states and settings.

    python -m cosim.sweep docs/sweeps/smc_vs_pd.toml             # local cluster, 1 worker/core
    python -m cosim.sweep SPEC --scheduler tcp://host:8786       # an existing Dask cluster
    python -m cosim.sweep SPEC --workers 2 --csv --out results/sweeps
    python -m cosim.sweep SPEC --backend inprocess               # our FMUs without FMI: faster

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

Each Dask task is one whole co-simulation with our master (``sweep_task``). The
client sends every FMU once, by content (``bundle``): a worker needs the project
installed, nothing else, and runs the client's code or is refused. A worker keeps
each system's FMUs per thread and resets them (fmi2Reset) between tasks.

A run's id hashes everything that determines its result (the system and its FMUs'
contents, the settings, the stop time, the axis values). results/sweeps/<name>/
runs.jsonl gets each row as it completes (``journal``), so an interrupted sweep
resumes where it stopped; failed runs are run again then (a deterministic failure
fails again at once, one caused by a lost worker deserves its retry).
results.parquet (and results.csv with --csv) hold the table at the end; a summary
is printed, figures are written, and comparison.md pairs every controller with pd
seed by seed. A task whose worker dies is retried twice, then recorded as failed;
an FMU error is recorded as failed at once, with its message. A sweep whose cluster
has had no worker for 60 s (``--no-worker-timeout``) stops as on Ctrl-C, every
row done kept, and says so.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import queue
import sys
import time
import tomllib
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from .. import scenarios
from ..analysis.seastate import model_scale
from ..core.inprocess import fallback_note
from ..core.provenance import PACKAGE, code_version
from ..scenarios.autopilot import check_autopilot
from .bundle import Bundle, bundle
from .cluster import connect
from .journal import Journal, JournalLocked, read_rows, write_atomically
from .sweep_task import (METRICS, Job, SweepTeardown, blank_row, fmu_bytes, run_one,
                         worker_facts)

DEFAULT_CONTROLLERS = {"pd": {"scenario": "waves_pd"}, "smc": {"scenario": "waves_smc"}}
# Axis shorthands: name -> the FMU parameter it sets.
SHORTHANDS = {"wave_seed": "ship.wave_seed", "Hs": "ship.Hs", "T0": "ship.T0",
              "psi_w": "ship.psi_w", "route": "guidance.waypoints"}
NO_WORKER_TIMEOUT = 60.0
"""Seconds a sweep waits while its cluster has no worker, then stops (``NoWorkers``)."""


@dataclass
class Spec:
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


# -- the client side --------------------------------------------------------------------
class SweepError(RuntimeError):
    """The sweep cannot start: a worker runs other code, or another sweep holds the journal."""


class NoWorkers(RuntimeError):
    """The sweep stopped: its cluster had no worker for as long as it waits for one. The
    runs completed stay in the journal, as on an interruption."""

    exit_status = 3
    """The command's exit status for it (0: every run ok, 1: some failed, 2: cannot start)."""


class _WorkerWatch:
    """Raises ``NoWorkers`` from ``check`` once the scheduler has counted no worker for
    ``timeout`` seconds; it is asked at most every ``interval`` seconds (1 s, or less for a
    short timeout), and only while the client waits."""

    def __init__(self, client, timeout: float):
        self.client, self.timeout = client, timeout
        self.interval = min(1.0, timeout / 4)
        self.seen = False                   # a worker was counted at least once
        self.gone_since: float | None = None
        self.gone_at = ""                   # when none was first counted, for the message
        self.next_check = 0.0
        self.check()

    def check(self) -> None:
        now = time.monotonic()
        if now < self.next_check:
            return
        self.next_check = now + self.interval
        try:
            workers = len(self.client.nthreads())
        except OSError:                     # the scheduler cannot be reached: no worker either
            workers = 0
        if workers:
            self.seen, self.gone_since = True, None
        elif self.gone_since is None:
            self.gone_since, self.gone_at = now, time.strftime("%Y-%m-%d %H:%M:%S")
        elif now - self.gone_since >= self.timeout:
            since = "the last one left by" if self.seen else "none has joined since"
            raise NoWorkers(f"no worker in the cluster for {self.timeout:g} s ({since} "
                            f"{self.gone_at}); the sweep stopped")

    def result(self, future):
        """``future.result()``, checking the cluster while it waits: a finished run's result
        is fetched from its worker, and computed again if that worker has just died."""
        from dask.distributed import TimeoutError

        while True:
            try:
                return future.result(timeout=self.interval)
            except TimeoutError:
                if future.status == "error":    # the task's own TimeoutError
                    raise
                self.check()


def _as_completed(futures: list, watch: _WorkerWatch) -> Iterator:
    """Each future as it completes, from its done callback (run by the future's own client,
    not the newest one); while none completes, ``watch`` is checked. Dask's ``as_completed``
    cannot do this: its timeout is a deadline for the whole iteration."""
    done: queue.SimpleQueue = queue.SimpleQueue()
    for future in futures:
        future.add_done_callback(done.put)
    for _ in futures:
        while True:
            try:
                yield done.get(timeout=watch.interval)
                break
            except queue.Empty:
                watch.check()


def _say(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run_locally(spec: Spec, run: dict[str, Any], backend: str = "fmi") -> dict[str, Any]:
    """One run of ``spec`` in this process, as a worker would do it."""
    job = spec.job(run, "local", backend)
    return run_one(job, {sha: spec.files()[sha].read_bytes() for sha in job.bundle.fmu_hashes()})


def check_workers(client) -> None:
    """SweepError naming each worker that runs other code than this client (or none of
    it); a warning for workers with more than one thread, or a scheduler that queues
    more than one run per thread."""
    mine = code_version()
    try:
        facts = client.run(worker_facts, on_error="return")
    except Exception as error:              # e.g. no worker can import cosim at all
        raise SweepError(f"cannot ask the workers what they run ({error})") from None
    wrong = []
    for address, fact in sorted(facts.items()):
        theirs = fact["code"] if isinstance(fact, dict) else f"none ({type(fact).__name__}: {fact})"
        if theirs != mine:
            wrong.append(f"  {address} runs {PACKAGE} {theirs}")
    if wrong:
        raise SweepError(f"workers run other code than this client ({PACKAGE} {mine}):\n"
                         + "\n".join(wrong) + "\ninstall the client's version on every worker "
                         "(a wheel: pip wheel --no-deps -w dist . ; pip install dist/*.whl)")
    threaded = {a: n for a, n in client.nthreads().items() if n > 1}
    if threaded:
        _say(f"warning: {', '.join(f'{a} has {n} threads' for a, n in threaded.items())}; a "
             "run holds the GIL from start to end, so threads of one worker take turns: start "
             "workers with --nthreads 1 and more processes (--nworkers)")
    saturation = client.run_on_scheduler(_worker_saturation)
    if saturation != 1.0:
        _say(f"warning: the scheduler's worker-saturation is {saturation}: it queues more than "
             "one run per worker thread, and a worker killed by one run takes the queued ones "
             "with it; start the scheduler with DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION=1.0")


def _has_dashboard(dask_scheduler=None) -> bool:
    """Whether the scheduler serves its dashboard (which needs bokeh where it runs)."""
    import importlib.util
    return ("dashboard" in dask_scheduler.services
            and importlib.util.find_spec("bokeh") is not None)


def _worker_saturation(dask_scheduler=None) -> float:
    """The running scheduler's worker-saturation (read at its start from Dask's config)."""
    return float(dask_scheduler.WORKER_SATURATION)


def execute(spec: Spec, out: Path, scheduler: str | None = None, workers: int | None = None,
            progress: bool = True, task=None, scheduler_file: str | None = None,
            backend: str = "fmi", no_worker_timeout: float = NO_WORKER_TIMEOUT) -> list[dict]:
    """Run every run of ``spec`` without an ok row in the journal (failed rows are run
    again); return every row of the sweep.

    ``backend``: the master's, "fmi" or "inprocess" (this project's FMUs as Python
    classes: the same results, faster; any other FMU runs through FMI,
    ``Spec.backend_notes`` says which). The backend is not part of a run's identity: a
    sweep may be resumed with the other.

    ``task(job, blobs) -> row`` is what each run executes (default ``run_one``). Each
    distinct FMU goes to the cluster once (``cosim.studies.bundle``); each run's future
    is released as soon as its row is journaled, so a lost worker costs only the runs
    it had in flight. On Ctrl-C or SIGTERM (``Interrupted``, raised again once the
    cluster is closed) the runs completed so far stay in the journal (``completed``);
    the same call then resumes. A cluster with no worker for ``no_worker_timeout``
    seconds ends the sweep the same way, with ``NoWorkers``. SweepError if a worker runs
    other code than the client or another sweep writes the journal.
    """
    if backend not in ("fmi", "inprocess"):
        raise ValueError(f"backend must be fmi or inprocess, got {backend!r}")
    if not 0 < no_worker_timeout < float("inf"):
        raise ValueError(f"no_worker_timeout must be a number of seconds > 0, got "
                         f"{no_worker_timeout!r}")
    try:
        with Journal(out / "runs.jsonl") as journal:
            runs = spec.runs()
            todo = [r for r in runs if journal.rows.get(r["run_id"], {}).get("status") != "ok"]
            if len(todo) < len(runs):
                _say(f"{len(runs) - len(todo)} of {len(runs)} runs already done in "
                     f"{journal.path}; {len(todo)} to run")
            if todo:
                _run_on_cluster(spec, todo, journal, connect(scheduler, workers, scheduler_file),
                                progress, task or run_one, backend, no_worker_timeout)
    except JournalLocked as locked:
        raise SweepError(str(locked)) from None
    return completed(spec, out)


def _run_on_cluster(spec: Spec, todo: list[dict], journal: Journal, connection, progress: bool,
                    task, backend: str, no_worker_timeout: float) -> None:
    client, cluster = connection
    token = uuid.uuid4().hex[:12]
    teardown = SweepTeardown(token)
    try:
        if client.run_on_scheduler(_has_dashboard):
            _say(f"dashboard: {client.dashboard_link}")
        check_workers(client)
        client.register_plugin(teardown)
        # Each FMU as a task holding its bytes, not scattered data: a task's result lost with
        # its worker is computed again, scattered data is gone, and every run with it. Keyed
        # by sweep: another sweep's release of a shared key would strand this one's runs.
        shipped = {sha: client.submit(fmu_bytes, path.read_bytes(), key=f"fmu-{token}-{sha}",
                                      pure=False)
                   for sha, path in spec.files().items()}
        futures = {}
        for run in todo:
            job = spec.job(run, token, backend)
            blobs = {sha: shipped[sha] for sha in job.bundle.fmu_hashes()}
            futures[client.submit(task, job, blobs, retries=2, pure=False,
                                  key=f"run-{token}-{run['run_id']}")] = run
        bar = None
        if progress:
            from tqdm import tqdm
            bar = tqdm(total=len(todo), desc=spec.name, unit="run", file=sys.stderr,
                       disable=None)                # None: only on a terminal
        watch = _WorkerWatch(client, no_worker_timeout)
        try:
            for future in _as_completed(list(futures), watch):
                try:
                    row = watch.result(future)
                except NoWorkers:
                    raise
                except Exception as error:      # the worker died on every retry
                    row = {**blank_row(futures[future], f"{type(error).__name__}: {error}"),
                           "backend": backend}
                journal.add(row)
                del futures[future]
                future.release()                # done: nothing to recompute if a worker dies
                if bar is not None:
                    bar.update()
        except NoWorkers:
            client.cancel([*futures, *shipped.values()])
            raise
        if bar is not None:
            bar.close()
    finally:
        if cluster is None:                     # a shared cluster: free this sweep's FMUs
            try:
                client.unregister_worker_plugin(teardown.name)
            except Exception:                   # workers gone with Ctrl-C
                pass
        client.close()
        if cluster is not None:                 # closing its workers frees everything
            cluster.close()


def completed(spec: Spec, out: Path) -> list[dict]:
    """The rows of ``spec``'s runs in its journal, in the order of ``spec.runs()``."""
    rows = read_rows(out / "runs.jsonl", quiet=True)
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
    written = [write_atomically(out / "results.parquet", lambda p: pq.write_table(table, p)),
               write_atomically(out / "results.json", lambda p: p.write_text(
                   json.dumps({"units": units}, indent=1) + "\n"))]
    if csv:
        written.append(write_atomically(out / "results.csv",
                                        lambda p: pacsv.write_csv(table, p)))
    return written


def summary(spec: Spec, rows: list[dict], shown_failures: int = 10) -> str:
    """Runs, ok and failed; J by controller; each failed run with its message."""
    ok = [r for r in rows if r["status"] == "ok"]
    lines = [f"{spec.name}: {len(rows)} runs, {len(ok)} ok, {len(rows) - len(ok)} failed"]
    for controller in spec.controllers:
        J = np.array([r["J"] for r in ok if r["controller"] == controller])
        if J.size:
            lines.append(f"  {controller:>14}: J median {np.median(J):9.2f}, mean {J.mean():9.2f}"
                         f", 5-95 % {np.percentile(J, 5):9.2f} - {np.percentile(J, 95):9.2f}"
                         f" ({J.size} runs)")
    failed = [r for r in rows if r["status"] != "ok"]
    for r in failed[:shown_failures]:
        axes = ", ".join(f"{a} = {r[a]}" for a in spec.axes)
        said = [line.strip() for line in r["error"].splitlines()[:2]]   # the call, the FMU's words
        lines.append(f"  failed {r['controller']} ({axes}): {' / '.join(said)[:300]}")
    if len(failed) > shown_failures:
        lines.append(f"  ... and {len(failed) - shown_failures} more failed runs (results.parquet "
                     "has every message)")
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
