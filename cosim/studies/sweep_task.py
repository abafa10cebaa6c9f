"""A sweep's task, on a worker: one whole co-simulation, from a ``Job`` and the FMUs' bytes.

A worker keeps one master per sweep, thread, system (``Bundle.digest``) and backend,
and resets it (fmi2Reset) between tasks. Each sweep registers its own ``SweepTeardown`` worker
plugin, named after the sweep's token: when the sweep ends (or the worker closes) it
frees that sweep's masters only, so two sweeps on one cluster do not free each
other's FMUs.
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
from ..core.provenance import code_version
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


def ran_on(master, asked: str) -> str:
    """How a run's components ran: "inprocess" or "fmi" if all alike, else each named
    ("inprocess; autopilot: fmi"); ``asked`` where no master was made."""
    if master is None:
        return asked
    kinds = master.backends
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
    row = blank_row(job.run)
    if job.code != code_version():          # a worker that joined after the client's check
        return blank_row(job.run, f"worker runs {code_version()}, the client {job.code}: "
                                  "install the client's version on every worker")
    master, watchdog = None, Watchdog(job.limits)
    try:
        with watchdog:                          # a hung FMU fails its run, not the worker
            watchdog.beat("instantiating the FMUs")
            master = _master(job, blobs)
            master.configure(job.overrides)
            simulating = time.perf_counter()
            recording = master.run(job.stop_time, watchdog=watchdog)
        row["sim_seconds"] = time.perf_counter() - simulating
    except (Exception, TimeLimit) as error:  # a bad setting: not worth retrying
        _drop_master(job)
        reason = watchdog.expired if watchdog.expired else f"{type(error).__name__}: {error}"
        row = blank_row(job.run, reason)
    else:
        if recording.error:
            _drop_master(job)               # its FMUs may be in an error state
            row = blank_row(job.run, recording.error)
        else:
            row.update(run_metrics(recording))
            if job.track:
                row["track"] = _track(recording)
    row["backend"] = ran_on(master, job.backend)   # the results are the same either way
    row["seconds"] = time.perf_counter() - started
    return row


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
