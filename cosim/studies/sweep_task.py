"""A sweep's tasks, on a worker: one whole co-simulation from a ``Job`` and the FMUs' bytes
(``run_one``), or a batch of runs of one system as one array program (``run_batch``).

Both make a run's row from its recording with one function (``result_row``), so a run's
row is the same, every column but ``backend``, ``seconds`` and ``sim_seconds``, whichever
task ran it. A worker keeps one master per sweep, thread, system (``Bundle.digest``) and
backend, and resets it (fmi2Reset) between tasks. Each sweep registers its own
``SweepTeardown`` worker plugin, named after the sweep's token: when the sweep ends (or
the worker closes) it frees that sweep's masters only, so two sweeps on one cluster do not
free each other's FMUs.
"""
from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from typing import Any

from distributed import WorkerPlugin

from autopilot_fmu.guidance import R_ACCEPT, route as followed_route

from ..analysis.cost import cost
from ..analysis.metrics import (cross_track_error, fraction_at_stops, heading_error,
                                mean_abs_rate, peak, rms, route_completion,
                                rudder_reversals_per_minute)
from ..core.master import RUN_BACKENDS
from ..provenance import code_version
from ..core.watchdog import Limits, TimeLimit, Watchdog
from .bundle import Bundle, materialise

METRICS = {"psi_E": "rad^2", "sum_delta2": "rad^2", "J": "rad^2",
           "rms_heading_error_deg": "deg", "reversals_per_min": "1/min", "max_delta_deg": "deg",
           "mean_rudder_rate_deg_s": "deg/s", "at_stops_pct": "%",
           "cross_track_rms_m": "m", "cross_track_max_m": "m",
           "waypoints_reached": "", "waypoints": "", "last_waypoint_reached": ""}
"""The figures of merit of a run and their units, as ``cosim.run`` prints them (angles in
degrees for display; ``run_metrics`` says what each is). Counts and the 0/1 flag have no
unit; every value is a float, NaN in a failed run's row."""


@dataclass(frozen=True)
class Criterion:
    """A column of ``METRICS`` as a criterion to compare controllers by."""
    column: str
    label: str
    lower_is_better: bool = True
    paired: str = "ratio"           # how a run is set beside another's: ratio or difference
    digits: int = 1                 # decimals shown
    out_of: str | None = None       # the column it is a count out of, if any

    @property
    def unit(self) -> str:
        return METRICS[self.column]

    @property
    def better(self) -> str:
        return "lower is better" if self.lower_is_better else "higher is better"

    def format(self, value: float, sign: str = "") -> str:
        """``value`` to this criterion's decimals (a median of counts may be a half: 2.5),
        '-' if it is not finite; ``sign="+"`` signs it."""
        if not math.isfinite(value):
            return "-"
        return f"{value:{sign}g}" if self.digits == 0 else f"{value:{sign}.{self.digits}f}"


CRITERIA = (
    Criterion("J", "J of eq (19)"),
    Criterion("rms_heading_error_deg", "RMS heading error psi_d - psi", paired="difference",
              digits=2),
    Criterion("reversals_per_min", "rudder reversals"),
    Criterion("mean_rudder_rate_deg_s", "mean abs rudder rate", digits=2),
    Criterion("at_stops_pct", "time on the rudder stops", paired="difference"),
    Criterion("cross_track_rms_m", "RMS cross-track error", paired="difference", digits=2),
    Criterion("cross_track_max_m", "max cross-track error", paired="difference", digits=2),
    Criterion("waypoints_reached", "waypoints reached", lower_is_better=False,
              paired="difference", digits=0, out_of="waypoints"),
)
"""The criteria a scorecard compares controllers by, each with the side that is better."""


@dataclass(frozen=True)
class Job:
    """One run as a worker receives it: nothing is read from the client's disk."""
    sweep: str                          # the sweep's token: whose masters these are
    run: dict[str, Any]                 # run_id, controller and axis values
    bundle: Bundle
    overrides: dict[str, dict[str, Any]]
    stop_time: float | None
    track: bool                         # record the track for the tracks figure
    code: str                           # the client's code_version(): the worker's must match
    backend: str = "fmi"                # the master's: fmi, or inprocess for our FMUs
    limits: Limits = Limits()           # the run's step and run time limits


_masters: dict[tuple[str, int, str, str], Any] = {}    # (sweep, thread, digest, backend)
_masters_lock = threading.Lock()


def _master(job: Job, blobs: dict[str, bytes]):
    from ..core.master import Master

    key = _key(job)
    with _masters_lock:
        master = _masters.get(key)
    if master is None:
        master = Master(materialise(job.bundle, blobs), backend=job.backend)
        with _masters_lock:
            _masters[key] = master
    else:
        master.reset()
    return master


def _key(job: Job) -> tuple[str, int, str, str]:
    return job.sweep, threading.get_ident(), job.bundle.digest, job.backend


def _drop_master(job: Job) -> None:
    with _masters_lock:
        master = _masters.pop(_key(job), None)
    if master is not None:
        master.free()


def free_masters(sweep: str | None = None) -> None:
    """Free this process's cached masters: of one sweep, or all."""
    with _masters_lock:
        keys = [k for k in _masters if sweep is None or k[0] == sweep]
        masters = [_masters.pop(k) for k in keys]
    for master in masters:
        master.free()


class SweepTeardown(WorkerPlugin):
    """Frees one sweep's masters (and their temporary folders) on a worker."""

    def __init__(self, sweep: str):
        self.sweep = sweep
        self.name = f"cosim-sweep-{sweep}"

    def teardown(self, worker) -> None:
        free_masters(self.sweep)


def ran_on(kinds: dict[str, str] | None, asked: str) -> str:
    """How a run's components ran (``kinds``: each component's backend, as
    ``Master.backends``): "inprocess" or "fmi" if all alike, else each named
    ("inprocess; autopilot: fmi"); ``asked`` where no master was made."""
    if not kinds:
        return asked
    if len(set(kinds.values())) == 1:
        return next(iter(kinds.values()))
    others = [f"{name}: {kind}" for name, kind in kinds.items() if kind != asked]
    return "; ".join([asked, *others])


def worker_facts() -> dict[str, Any]:
    """What the client checks of a worker before it sends work: the code it runs."""
    return {"code": code_version()}


def fmu_bytes(data: bytes) -> bytes:
    """An FMU's file, as a task's result: what each run of its system depends on."""
    return data


def blank_row(run: dict[str, Any], error: str = "") -> dict[str, Any]:
    """A result row for ``run``: failed with ``error`` if given, metrics still undefined."""
    return {**run, "status": "failed" if error else "ok", "error": error,
            **{m: math.nan for m in METRICS}, "seconds": math.nan, "sim_seconds": math.nan}


def run_one(job: Job, blobs: dict[str, bytes]) -> dict[str, Any]:
    """One whole co-simulation; never raises for a failed run, records it. ``seconds`` is
    the task's wall time, ``sim_seconds`` the master's run alone. A run past its time
    limits fails (``core.watchdog``; one whose FMU runs no Python ends the worker, and
    the sweep retries it, then records it failed, as any run that kills its worker)."""
    started = time.perf_counter()
    if job.code != code_version():          # a worker that joined after the client's check
        return _other_code(job)
    master, watchdog = None, Watchdog(job.limits)
    try:
        with watchdog:                          # a hung FMU fails its run, not the worker
            watchdog.beat("instantiating the FMUs")
            master = _master(job, blobs)
            master.configure(job.overrides)
            simulating = time.perf_counter()
            recording = master.run(job.stop_time, watchdog=watchdog)
        sim_seconds = time.perf_counter() - simulating
    except (Exception, TimeLimit) as error:  # a bad setting: not worth retrying
        _drop_master(job)
        reason = watchdog.expired if watchdog.expired else f"{type(error).__name__}: {error}"
        row = blank_row(job.run, reason)
    else:
        if recording.error:
            _drop_master(job)               # its FMUs may be in an error state
        row = result_row(job, recording)
        if not recording.error:
            row["sim_seconds"] = sim_seconds
    row["backend"] = ran_on(master and master.backends, job.backend)   # same results either way
    row["seconds"] = time.perf_counter() - started
    return row


def _other_code(job: Job) -> dict[str, Any]:
    """The failed row of a run sent by a client that runs other code than this worker."""
    return blank_row(job.run, f"worker runs {code_version()}, the client {job.code}: "
                              "install the client's version on every worker")


def result_row(job: Job, recording) -> dict[str, Any]:
    """The row of ``job``'s run from its recording, whichever route made it: failed with the
    recording's error, else every figure of merit (``run_metrics``) and, if the job asks,
    the track; the times and the backend are the caller's to fill in."""
    if recording.error:
        return blank_row(job.run, recording.error)
    row = {**blank_row(job.run), **run_metrics(recording)}
    if job.track:
        row["track"] = _track(recording)
    return row


BATCH = "batch"
"""The sweep backend that runs the runs of one system as batches (``run_batch``)."""
SWEEP_BACKENDS = (*RUN_BACKENDS, BATCH)
"""The backends a sweep may take: a master's (``RUN_BACKENDS``), or batches."""


def batch_refusal() -> str | None:
    """Why this worker would not give the in-process route's bits on the batch route
    (``cosim.ensemble.selftest``, run once per process), None if it would."""
    from ..ensemble import selftest

    try:
        return selftest()
    except Exception as error:          # a self-test that cannot run refuses the route
        return f"its self-test failed: {type(error).__name__}: {error}"


def batch_limits(limits: Limits, members: int) -> Limits:
    """A batch's time limits: each per-run limit times its ``members``."""
    return Limits(None if limits.step is None else limits.step * members,
                  None if limits.run is None else limits.run * members, limits.grace)


def run_batch(jobs: list[Job], blobs: dict[str, bytes]) -> list[dict[str, Any]]:
    """The rows of ``jobs`` (runs of one system and stop time, in-process jobs) in their
    order, computed together by the batch kernel (``cosim.ensemble.simulate_members``);
    never raises for a failed run.

    Each row is the row ``run_one`` makes of the job but for ``backend`` ("batch", or
    what the member ran on and why), ``seconds`` and ``sim_seconds`` (the member's share
    of the batch). A member ``Master.configure`` refuses is run by ``run_one`` (which
    refuses it the same way); every member is, saying why in its backend, where
    ``batch_refusal`` refuses the route on this worker or the batch fails as a whole (an
    exception, or its time limits passed, ``batch_limits``: each member's initialisation
    and each step of the members together within N times the step limit, the batch
    within N times the run limit; the kernel stops at the step after a limit passed)."""
    from ..ensemble import simulate_members

    started = time.perf_counter()
    if any(job.code != code_version() for job in jobs):
        return [_other_code(job) for job in jobs]
    refusal = batch_refusal()
    if refusal:
        return _one_by_one(jobs, blobs, f"the batch route is refused on this worker: {refusal}")
    watchdog = Watchdog(batch_limits(jobs[0].limits, len(jobs)))
    try:
        with watchdog:
            watchdog.beat("instantiating the FMUs")
            master = _master(jobs[0], blobs)
            members = [job for job in jobs if _configures(master, job)]
            watchdog.beat(f"the batch of {len(members)} runs")
            recordings = simulate_members(master.system, [job.overrides for job in members],
                                          jobs[0].stop_time, beat=watchdog.beat
                                          ) if members else []
        if watchdog.expired:
            raise TimeLimit(watchdog.expired)
    except (Exception, TimeLimit) as error:
        reason = watchdog.expired if watchdog.expired else f"{type(error).__name__}: {error}"
        return _one_by_one(jobs, blobs, f"the batch failed, {reason}; run alone")
    share = (time.perf_counter() - started) / max(1, len(members))
    rows = {}
    for job, recording in zip(members, recordings, strict=True):
        row = result_row(job, recording)
        if not recording.error:
            row["sim_seconds"] = recording.meta["wall_time_s"]
        rows[job.run["run_id"]] = {**row, "backend": member_backend(recording.meta),
                                   "seconds": share}
    return [rows.get(job.run["run_id"]) or run_one(job, blobs) for job in jobs]


def _configures(master, job: Job) -> bool:
    """Whether ``Master.configure`` takes ``job``'s settings."""
    try:
        master.configure(job.overrides)
    except Exception:                   # run_one records why
        return False
    return True


def _one_by_one(jobs: list[Job], blobs: dict[str, bytes], why: str) -> list[dict[str, Any]]:
    """``run_one`` of each job, its backend saying ``why`` it did not run in a batch."""
    return [noted(run_one(job, blobs), why) for job in jobs]


def noted(row: dict[str, Any], why: str) -> dict[str, Any]:
    """``row`` with ``why`` its run did not run in a batch added to its backend."""
    return {**row, "backend": f"{row.get('backend', 'inprocess')} (not in a batch: {why})"}


def member_backend(meta: dict[str, Any]) -> str:
    """A batch member's backend column, from its recording's meta: "batch", or how it ran
    alone and why (the kernel's notes: "ran on the in-process route, not in the batch: ...")."""
    if meta.get("backend") == BATCH:
        return BATCH
    ran = ran_on(meta.get("backends"), meta.get("backend", "inprocess"))
    notes = "; ".join(meta.get("notes") or [])
    return f"{ran} ({notes})" if notes else ran


def _track(recording, every: float = 1.0) -> dict:
    """The run's track every ``every`` s, its route and circle of acceptance, for the
    tracks figure."""
    stride = max(1, round(every / recording.meta["step_size"]))
    points, R_accept = route_of(recording)
    return {"x": recording["ship.x"][::stride].tolist(),
            "y": recording["ship.y"][::stride].tolist(),
            "route": [list(point) for point in points], "R_accept": R_accept}


def route_of(recording) -> tuple[list[tuple[float, float]], float]:
    """The route the run's guidance followed (m) and its radius of acceptance (m), from the
    parameter values the FMUs used."""
    guidance = recording.meta.get("parameters", {}).get("guidance", {})
    return followed_route(guidance), float(guidance.get("R_accept", R_ACCEPT))


def run_metrics(recording) -> dict[str, float]:
    """Every figure of merit of ``METRICS`` of a course-keeping run: eq (19); the RMS
    heading error psi_d - psi; from the actual rudder ship.delta its largest angle, its
    reversals per minute, its mean absolute rate and the time on its stops; the RMS and
    largest cross-track error from the leg the guidance follows; and the waypoints of the
    route reached, within the circle of acceptance, of those it has."""
    c = cost(recording)
    t, delta, x, y = (recording.t, recording["ship.delta"], recording["ship.x"],
                      recording["ship.y"])
    points, R_accept = route_of(recording)
    stops = recording.meta.get("parameters", {}).get("ship", {}).get("delta_max", math.inf)
    track = cross_track_error(x, y, recording["guidance.wp_index"], points)
    completion = route_completion(x, y, points, R_accept)
    return {"psi_E": c.psi_E, "sum_delta2": c.sum_delta2, "J": c.J,
            "rms_heading_error_deg": math.degrees(rms(heading_error(
                recording["guidance.psi_d"], recording["ship.psi"]))),
            "reversals_per_min": rudder_reversals_per_minute(t, delta),
            "max_delta_deg": math.degrees(peak(delta)),
            "mean_rudder_rate_deg_s": math.degrees(mean_abs_rate(t, delta)),
            "at_stops_pct": 100.0 * fraction_at_stops(delta, stops),
            "cross_track_rms_m": rms(track), "cross_track_max_m": peak(track),
            "waypoints_reached": float(completion.count), "waypoints": float(len(points)),
            "last_waypoint_reached": float(completion.last_reached)}
