"""The scorecard: your autopilot beside the paper's PD and sliding-mode ones and the PID.

Every controller runs the same tests and is scored on several criteria, each with its unit
and the side that is better (``merit.CRITERIA``: J of eq (19), RMS heading error,
rudder reversals per minute and mean |rudder rate| of the actual rudder, time on the stops,
RMS and largest cross-track error, waypoints reached). There is no overall rank: each
criterion is won or lost on its own.

- **the paper's route**, in calm water and in waves (Tables 1-2), one run each;
- **a course change**: 40 deg from steady straight running in calm water, 300 s:
  settling time to 2 % (0.8 deg), overshoot, rudder activity, cross-track error;
- **two wave ensembles**: the route over N wave seeds in the paper's waves and in WMO sea
  state 4, on Dask through the sweep machinery (on its batch backend with
  ``backend="batch"``): each criterion's median and IQR, and,
  seed-paired against the PD (the same sea for both), wins, losses and ties out of the N
  seeds with the median paired ratio or difference.

Route completion (waypoints reached within the circle of acceptance, the last one
included or not) is reported for every test that follows the route.

``score`` runs them, writes scorecard.md and the figures, and each single run's CSV and
metadata in runs/ (through ``cosim.outputs``, as ``cosim.run`` does), and returns the
markdown.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from autopilot_fmu.guidance import parse_waypoints

from ..analysis.cost import Cost, cost
from ..analysis.figures import comparison_figure
from ..analysis.metrics import (RUDDER_DEADBAND, RouteCompletion, heading_error, overshoot,
                                route_completion, settling_time)
from ..analysis.reports import PAPER_TABLES
from ..analysis.seastate import WMO, model_scale
from .. import scenarios
from ..api import SimulationError, overrides_of
from ..core.files import fresh_folder, write_atomically
from ..core.recording import Recording
from ..outputs import Options, run_and_write
from .campaign import execute
from .spec_file import controller_entry
from .sweep_spec import Spec
from .sweep_figures import STATISTICS, distribution, paired_figure, tracks
from .merit import CRITERIA, Merit, route_of, run_metrics
from .sweep_task import BATCH

BASELINES = {"PD": "pd", "SMC": "smc", "PID": "pid"}
"""The project's autopilots by display name: scenarios <sea>_<suffix>."""
BASELINE = "PD"
"""The controller every other is paired with, seed by seed."""
COURSE_CHANGE = math.radians(40.0)
COURSE_CHANGE_ROUTE = f"0,0;1000,{1000 * math.tan(COURSE_CHANGE)!r}"
"""One long leg at 40 deg: the ship, heading north at t = 0, turns onto it."""
COURSE_CHANGE_TIME = 300.0
SETTLING_BAND = 0.02 * COURSE_CHANGE
HEAVY_SEA = 4
"""The WMO sea state code of the second ensemble: moderate, where the rudder saturates."""
TIE = 0.01
"""Two values closer than this share of the baseline's are a tie, not a win."""


@dataclass(frozen=True)
class Contender:
    """A controller of the scorecard: the project's (``suffix``) or the user's (``fmu``)."""

    name: str
    suffix: str = "pd"                   # scenarios <sea>_<suffix>
    fmu: Path | None = None              # in place of that scenario's autopilot
    port_map: dict[str, str] | None = None
    settings: dict[str, Any] | None = None   # --set values, for the user's autopilot only

    def run(self, label: str, out: Path, sea: str, stop_time: float | None = None,
            route: str | None = None, backend: str = "fmi") -> Recording:
        """The run of a test, its CSV and metadata written to out/<label>_<name>.*
        (``cosim.outputs``); SimulationError if an FMU fails."""
        settings = dict(self.settings or {})
        if route is not None:
            settings["guidance.waypoints"] = route
        system = scenarios.load(f"{sea}_{self.suffix}", self.fmu, self.port_map)
        out.mkdir(parents=True, exist_ok=True)
        outcome = run_and_write(system, f"{label}_{self.name}", out,
                                overrides_of(settings),   # notes: said once, up front
                                Options(stop_time=stop_time, backend=backend, plot=False))
        if outcome.recording.error:
            raise SimulationError(outcome.recording.error, outcome.recording)
        return outcome.recording


@dataclass(frozen=True)
class Sea:
    """The sea of a wave ensemble: the scenarios' own (the paper's) or a WMO code's."""

    key: str                             # in file names: ensemble_<key>, criteria_<key>.png
    name: str                            # "the paper's waves"
    detail: str                          # its Hs and T0
    sea_state: int | None = None         # WMO code; None: the waves_* scenarios' waves

    @property
    def title(self) -> str:
        return f"{self.name} ({self.detail})"


def _heavy_sea() -> Sea:
    Hs, T0 = model_scale(HEAVY_SEA)
    description, Hs_full, _ = WMO[HEAVY_SEA]
    return Sea(f"sea_state_{HEAVY_SEA}", f"WMO sea state {HEAVY_SEA}, {description}",
               f"Hs {Hs * 1000:.1f} mm, T0 {T0:.2f} s at 1:70; {Hs_full:g} m full scale",
               HEAVY_SEA)


SEAS = (Sea("waves", "the paper's waves", "Hs 5 mm, T0 0.8 s"), _heavy_sea())


@dataclass(frozen=True)
class CourseChange:
    settling_time: float          # s, inf if it never settles within the run
    overshoot: float              # rad
    metrics: dict[str, float]     # merit.run_metrics of the run


def course_change(run: Recording) -> CourseChange:
    """Figures of merit of the 40 deg course change."""
    psi = run["ship.psi"]
    error = heading_error(run["guidance.psi_d"], psi)
    return CourseChange(settling_time(run.t, error, SETTLING_BAND),
                        overshoot(psi, psi[0], psi[0] + COURSE_CHANGE), run_metrics(run))


def completion(run: Recording) -> RouteCompletion:
    """Which waypoints of its route a run reached."""
    points, R_accept = route_of(run)
    return route_completion(run["ship.x"], run["ship.y"], points, R_accept)


@dataclass(frozen=True)
class Paired:
    """One criterion of a controller against the baseline over the seeds both ran."""

    wins: int
    losses: int
    ties: int
    median: float                 # of the paired ratios or differences; nan if none

    @property
    def seeds(self) -> int:
        return self.wins + self.losses + self.ties

    @property
    def verdict(self) -> str:
        """better / worse: on more than half the seeds; else even (mostly ties) or mixed."""
        if 2 * self.wins > self.seeds:
            return "better"
        if 2 * self.losses > self.seeds:
            return "worse"
        return "even" if 2 * self.ties > self.seeds else "mixed"


def pairs(criterion: Merit, rows: list[dict], controller: str,
          baseline: str = BASELINE) -> tuple[np.ndarray, np.ndarray]:
    """(controller's, baseline's) values of ``criterion`` on the seeds both ran ok, seed by
    seed (the rows of one ensemble, paired by wave_seed)."""
    values = {name: {r["wave_seed"]: r[criterion.column] for r in rows
                     if r["status"] == "ok" and r["controller"] == name}
              for name in (controller, baseline)}
    seeds = sorted(set(values[controller]) & set(values[baseline]))
    return (np.array([values[controller][s] for s in seeds], dtype=float),
            np.array([values[baseline][s] for s in seeds], dtype=float))


def change(criterion: Merit, mine: np.ndarray, base: np.ndarray) -> np.ndarray:
    """The paired ratios mine / base (where base is not 0) or differences mine - base."""
    if criterion.paired == "ratio":
        return mine[base != 0] / base[base != 0]
    return mine - base


def paired(criterion: Merit, rows: list[dict], controller: str,
           baseline: str = BASELINE) -> Paired:
    """``controller`` against ``baseline`` on ``criterion`` over the seeds of one ensemble:
    a win is the better value on the same sea, by more than ``TIE`` of the baseline's."""
    mine, base = pairs(criterion, rows, controller, baseline)
    sign = 1.0 if criterion.lower_is_better else -1.0
    margin = sign * (base - mine)                # > 0: mine is better
    tied = np.abs(margin) <= TIE * np.abs(base)
    wins, losses = int(np.sum((margin > 0) & ~tied)), int(np.sum((margin < 0) & ~tied))
    changes = change(criterion, mine, base)
    return Paired(wins, losses, int(np.sum(tied)),
                  float(np.median(changes)) if changes.size else math.nan)


def score(fmu: Path, name: str, out: Path, seeds: int = 20, port_map: dict | None = None,
          settings: dict[str, Any] | None = None, workers: int | None = None,
          scheduler: str | None = None,
          progress: Callable[[str], None] = lambda step: None, backend: str = "fmi") -> str:
    """Run the scorecard of ``fmu`` (called ``name``), write out/scorecard.md and figures.

    A run that fails (an FMU error) is reported in the tables as failed, with its message,
    and the scorecard goes on. ``backend="inprocess"`` runs this project's FMUs without
    FMI (the same results, faster); ``fmu`` then still runs through FMI unless it is one
    of ours (``cosim.core.inprocess.in_process_refusal``). ``backend="batch"`` runs the
    ensembles on the sweeps' batch backend (``cosim.studies.campaign.execute``: the same rows
    as in-process; ``fmu``'s runs alone in-process unless the batch kernel covers it) and
    the single runs in-process.
    """
    contenders = _contenders(fmu, name, port_map, settings)
    failures: dict[tuple[str, str], str] = {}
    single = "inprocess" if backend == BATCH else backend

    def attempt(contender: Contender, test: str, label: str, **kwargs) -> Recording | None:
        progress(f"{test}, {contender.name}")
        try:
            return contender.run(label, out / "runs", **kwargs, backend=single)
        except SimulationError as error:
            failures[contender.name, test] = str(error).splitlines()[0]
            return None

    route: dict[str, dict[str, Recording]] = {}
    for sea in ("calm", "waves"):
        runs = {c.name: attempt(c, f"{sea} water", f"route_{sea}", sea=sea)
                for c in contenders}
        route[sea] = {n: r for n, r in runs.items() if r is not None}
        comparison_figure(route[sea], out / f"route_{sea}.png",
                          f"The paper's route in {'calm water' if sea == 'calm' else 'waves'}")
    runs = {c.name: attempt(c, "course change", "course_change", sea="calm",
                            stop_time=COURSE_CHANGE_TIME, route=COURSE_CHANGE_ROUTE)
            for c in contenders}
    runs = {n: r for n, r in runs.items() if r is not None}
    changes = {n: course_change(r) for n, r in runs.items()}
    comparison_figure(runs, out / "course_change.png",
                      "40 deg course change from straight running, calm water")
    ensembles = {}
    for sea in SEAS:
        progress(f"wave ensemble in {sea.name}, {seeds} seeds on Dask")
        ensembles[sea] = _run_ensemble(contenders, seeds, sea, out, scheduler, workers,
                                       backend)
    text = _markdown(fmu, name, seeds, contenders, route, changes, failures, ensembles)
    write_atomically(out / "scorecard.md", lambda path: path.write_text(text))
    return text


def _contenders(fmu: Path, name: str, port_map: dict | None,
                settings: dict[str, Any] | None) -> list[Contender]:
    return [*(Contender(label, suffix) for label, suffix in BASELINES.items()),
            Contender(name, fmu=fmu, port_map=port_map, settings=settings)]


def _ensemble(contenders: list[Contender], seeds: int, out: Path, sea: Sea = SEAS[0]) -> Spec:
    """A wave ensemble: every contender on the paper's route in ``sea``, over ``seeds``."""
    entries = {c.name: ({"scenario": f"waves_{c.suffix}"} if c.fmu is None else
                        {"autopilot": str(c.fmu), "map": c.port_map or {},
                         "set": c.settings or {}})
               for c in contenders}
    axes: dict[str, list] = {"wave_seed": list(range(1, seeds + 1))}
    if sea.sea_state is not None:
        axes["sea_state"] = [sea.sea_state]
    return Spec(name=f"ensemble in {sea.name}", axes=axes,
                controllers={n: controller_entry(e, out / "scorecard", n)
                             for n, e in entries.items()}, tracks={})   # every track


def _run_ensemble(contenders: list[Contender], seeds: int, sea: Sea, out: Path,
                  scheduler: str | None, workers: int | None,
                  backend: str) -> tuple[Spec, list[dict]]:
    """Run one ensemble in a fresh folder, draw its figures; (its spec, its rows)."""
    spec = _ensemble(contenders, seeds, out, sea)
    folder = out / ("ensemble" if sea is SEAS[0] else f"ensemble_{sea.key}")
    with fresh_folder(folder) as ensemble:              # a fresh ensemble every time
        rows = execute(spec, ensemble, scheduler=scheduler, workers=workers, progress=False,
                       backend=backend)
    distribution(spec, rows, out / f"criteria_{sea.key}.png", CRITERIA)
    others = [c.name for c in contenders if c.name != BASELINE]
    paired_figure(f"The route in {sea.name}", {
        criterion: {name: change(criterion, *pairs(criterion, rows, name)) for name in others}
        for criterion in CRITERIA}, BASELINE, out / f"paired_{sea.key}.png")
    tracks(spec, rows, out / f"tracks_{sea.key}.png")
    return spec, rows


def backend_notes(fmu: Path, name: str, port_map: dict | None, backend: str) -> list[str]:
    """Which FMUs of the scorecard (the project's and ``fmu``) run through FMI although
    ``backend`` is "inprocess" or "batch", and on "batch" which contenders' ensemble runs
    run alone in-process (``Spec.backend_notes``): the ensemble's systems hold every FMU
    the scorecard runs."""
    return _ensemble(_contenders(fmu, name, port_map, None), 1, fmu.parent).backend_notes(
        backend)


def _cell(criterion: Merit, row: dict) -> str:
    """A run's value of ``criterion``, '3 of 4' for a count."""
    total = f" of {row[criterion.out_of]:.0f}" if criterion.out_of else ""
    return criterion.format(row[criterion.column]) + total


def _heading(criterion: Merit) -> str:
    unit = f" ({criterion.unit})" if criterion.unit else ""
    return f"{criterion.label}{unit}, {criterion.better}"


def _reached(done: RouteCompletion) -> str:
    """'reached 3 of 4 waypoints, the last included', plainly."""
    last = "the last included" if done.last_reached else "**not** the last"
    return f"reached {done.count} of {len(done.points)} waypoints, {last}"


def _misses(done: RouteCompletion) -> str:
    """The waypoints not reached, numbered from 1 (the start), with how far off."""
    return ", ".join(f"waypoint {k} ({x:g}, {y:g}) by {d:.1f} m"
                     for k, ((x, y), d, hit) in enumerate(
                         zip(done.points, done.closest, done.reached), start=1) if not hit)


def _markdown(fmu: Path, name: str, seeds: int, contenders: list[Contender],
              route: dict[str, dict[str, Recording]], changes: dict[str, CourseChange],
              failures: dict[tuple[str, str], str],
              ensembles: dict[Sea, tuple[Spec, list[dict]]]) -> str:
    names = [c.name for c in contenders]
    lines = [f"# Scorecard: {name}", "",
             f"Autopilot `{fmu}` beside the paper's PD and sliding-mode (SMC) autopilots and "
             "the project's PID, on CyberShip II (docs/own_autopilot.md says how each is run).",
             "Each criterion is scored on its own, with its unit and the side that is better; "
             "there is no overall rank. Angles in degrees, distances in m; a waypoint is "
             "reached when the ship comes within the guidance's circle of acceptance of it "
             "(waypoints are numbered from 1, the start); a rudder reversal is a crossing "
             "from one side to the other, counted once the rudder is "
             f"{math.degrees(RUDDER_DEADBAND):g} deg past amidships on the new side.", ""]
    lines += _at_a_glance(names, route, ensembles, seeds)
    lines += _paper_route(contenders, route)
    lines += _course_change(names, changes)
    for sea, (spec, rows) in ensembles.items():
        lines += _ensemble_section(sea, names, seeds, rows)
    if failures:
        lines += ["## Runs that failed", ""]
        lines += [f"- {name}, {test}: `{message[:200]}`"
                  for (name, test), message in failures.items()]
        lines.append("")
    return "\n".join(lines)


def _at_a_glance(names: list[str], route: dict[str, dict[str, Recording]],
                 ensembles: dict[Sea, tuple[Spec, list[dict]]], seeds: int) -> list[str]:
    """Results up front: each controller's criteria won and lost against the PD in each
    ensemble, and route completion in every test that follows the route."""
    lines = [f"## At a glance: each controller against the {BASELINE}", "",
             f"Seed-paired over {seeds} wave seeds: **better** (**worse**) means better "
             f"(worse) than the {BASELINE} on the same sea in more than half of the seeds, "
             f"*even* that most are ties (within {100 * TIE:g} % of the {BASELINE}'s value), "
             "*mixed* neither; then the seeds won, lost and tied of those both ran, and the "
             f"median paired ratio to the {BASELINE} or difference from it.", ""]
    for sea, (_, rows) in ensembles.items():
        lines += [f"The route in {sea.title}:", "",
                  "| criterion | better | " + " | ".join(names[1:]) + " |",
                  "|---|---|" + "---|" * len(names[1:])]
        for criterion in CRITERIA:
            cells = [_verdict(criterion, paired(criterion, rows, name)) for name in names[1:]]
            unit = f" ({criterion.unit})" if criterion.unit else ""
            lines.append(f"| {criterion.label}{unit} | {criterion.better.split()[0]} | "
                         + " | ".join(cells) + " |")
        lines.append("")
    lines += ["Route completion (higher is better):", "",
              "| controller | calm water | waves | "
              + " | ".join(f"ensemble, {sea.name}" for sea in ensembles) + " |",
              "|---|---|---|" + "---|" * len(ensembles)]
    for name in names:
        cells = [_reached(completion(route[sea][name])) if name in route[sea] else "failed"
                 for sea in ("calm", "waves")]
        cells += [_ensemble_completion(rows, name) for _, rows in ensembles.values()]
        lines.append(f"| {name} | {' | '.join(cells)} |")
    lines.append("")
    for sea, (_, rows) in ensembles.items():
        lines += _never_finished(sea, names, rows)
    return lines + [""]


def _never_finished(sea: Sea, names: list[str], rows: list[dict]) -> list[str]:
    """A plain sentence for each controller that reached the last waypoint in no seed."""
    lines = []
    for name in names:
        ok = [r for r in rows if r["status"] == "ok" and r["controller"] == name]
        if ok and not any(r["last_waypoint_reached"] == 1.0 for r in ok):
            stops = np.median([r["at_stops_pct"] for r in ok])
            held = f", the rudder on its stops a median {stops:.0f} % of the run" if stops else ""
            lines.append(f"- In {sea.name}, **{name} never reached the last waypoint** in any "
                         f"of {len(ok)} seeds: it {_waypoints_reached(ok)}{held}.")
    return lines


def _verdict(criterion: Merit, p: Paired) -> str:
    """'**better**: won 18, lost 2, tied 0 of 20; median ratio 0.13'."""
    if not p.seeds:
        return "no seed ran for both"
    word = f"**{p.verdict}**" if p.verdict in ("better", "worse") else f"*{p.verdict}*"
    return (f"{word}: won {p.wins}, lost {p.losses}, tied {p.ties} of {p.seeds}; "
            f"{_change(criterion, p.median)}")


def _change(criterion: Merit, median: float) -> str:
    """The median paired ratio or difference, with its unit."""
    if criterion.paired == "ratio":
        return f"median ratio {median:.2f}" if math.isfinite(median) else "no ratio"
    unit = {"": "", "%": " percentage points"}.get(criterion.unit, f" {criterion.unit}")
    return f"median difference {criterion.format(median, '+')}{unit}"


def _ensemble_completion(rows: list[dict], name: str) -> str:
    """'reached 3 of 4 waypoints; the last in 18 of 20 seeds'."""
    ok = [r for r in rows if r["status"] == "ok" and r["controller"] == name]
    if not ok:
        return "no run ok"
    last = sum(r["last_waypoint_reached"] == 1.0 for r in ok)
    return f"{_waypoints_reached(ok)}; the last in {last} of {len(ok)} seeds"


def _waypoints_reached(ok: list[dict]) -> str:
    """'reached 3 of 4 waypoints' over runs that ran ok: the count, or its median and range."""
    reached = np.array([r["waypoints_reached"] for r in ok])
    spread = (f"{reached.min():.0f}" if reached.min() == reached.max() else
              f"a median {np.median(reached):g} (from {reached.min():.0f} to "
              f"{reached.max():.0f})")
    return f"reached {spread} of {ok[0]['waypoints']:.0f} waypoints"


def _paper_route(contenders: list[Contender],
                 route: dict[str, dict[str, Recording]]) -> list[str]:
    lines = ["## The paper's route (Tables 1-2, eq 19; lower is better)", "",
             "| controller | calm psi_E | calm delta_E | calm J | waves psi_E | waves delta_E "
             "| waves J | paper J calm / waves |", "|---|---|---|---|---|---|---|---|"]
    costs = {(n, sea): cost(r) for sea, runs in route.items() for n, r in runs.items()}
    for c in contenders:
        cells = []
        for sea in ("calm", "waves"):
            r: Cost | None = costs.get((c.name, sea))
            cells += ([f"{r.psi_E:.1f}", f"{r.delta_E:.1f}", f"{r.J:.1f}"] if r
                      else ["failed"] * 3)
        theirs = (f"{PAPER_TABLES[f'calm_{c.suffix}'][2]:.1f} / "
                  f"{PAPER_TABLES[f'waves_{c.suffix}'][2]:.1f}"
                  if c.fmu is None and f"calm_{c.suffix}" in PAPER_TABLES else "-")
        lines.append(f"| {c.name} | {' | '.join(cells)} | {theirs} |")
    lines += ["", "Every criterion, one run each (the scenarios' wave seed):", "",
              "| controller | sea | " + " | ".join(_heading(c) for c in CRITERIA) + " |",
              "|---|---|" + "---|" * len(CRITERIA)]
    misses = []
    for sea, runs in route.items():
        for name, run in runs.items():
            row = run_metrics(run)
            lines.append(f"| {name} | {sea} | "
                         + " | ".join(_cell(c, row) for c in CRITERIA) + " |")
            done = completion(run)
            if done.count < len(done.points):
                misses.append(f"- {name}, {sea}: {_reached(done)}; missed {_misses(done)} "
                              f"(circle of acceptance {done.R_accept:g} m)")
    lines += ["", *misses, "", "![route in calm water](route_calm.png)",
              "![route in waves](route_waves.png)", ""]
    return lines


def _course_change(names: list[str], changes: dict[str, CourseChange]) -> list[str]:
    lines = [f"## A 40 deg course change, calm water, {COURSE_CHANGE_TIME:.0f} s (lower is "
             "better)", "",
             "| controller | settling time to 2 % (s) | overshoot (deg) | rudder reversals "
             "(1/min) | mean abs rudder rate (deg/s) | max rudder (deg) | max cross-track (m) |",
             "|---|---|---|---|---|---|---|"]
    for name in names:
        r = changes.get(name)
        if r is None:
            lines.append(f"| {name} |" + " failed |" * 6)
            continue
        settled = f"{r.settling_time:.1f}" if math.isfinite(r.settling_time) else \
            f"> {COURSE_CHANGE_TIME:.0f}"
        m = r.metrics
        lines.append(f"| {name} | {settled} | {math.degrees(r.overshoot):.2f} | "
                     f"{m['reversals_per_min']:.1f} | {m['mean_rudder_rate_deg_s']:.2f} | "
                     f"{m['max_delta_deg']:.1f} | {m['cross_track_max_m']:.2f} |")
    (x0, y0), (x1, y1) = parse_waypoints(COURSE_CHANGE_ROUTE)
    return lines + ["", f"The course change follows one leg of {math.hypot(x1 - x0, y1 - y0):.0f}"
                        f" m, longer than the ship sails in {COURSE_CHANGE_TIME:.0f} s: route "
                        "completion does not apply to it.", "",
                    "![course change](course_change.png)", ""]


def _ensemble_section(sea: Sea, names: list[str], seeds: int, rows: list[dict]) -> list[str]:
    """Each criterion's spread per controller (their pairing with the PD is up front)."""
    lines = [f"## Wave ensemble: the route in {sea.title}, {seeds} wave seeds", "",
             "Each criterion: median [IQR, 25-75 %] over the seeds that ran; waypoints "
             "reached out of the route's.", "",
             "| controller | runs ok | " + " | ".join(_heading(c) for c in CRITERIA) + " |",
             "|---|---|" + "---|" * len(CRITERIA)]
    ok = [r for r in rows if r["status"] == "ok"]
    for name in names:
        mine = [r for r in ok if r["controller"] == name]
        cells = [_spread(c, mine) for c in CRITERIA]
        lines.append(f"| {name} | {len(mine)}/{seeds} | {' | '.join(cells)} |")
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        lines += ["", f"{len(failed)} runs of the ensemble failed; the first: "
                      f"`{failed[0]['error'].splitlines()[0][:200]}`"]
    return lines + ["", f"![each criterion](criteria_{sea.key}.png) ({STATISTICS})",
                    f"![each criterion against the {BASELINE}, seed by seed]"
                    f"(paired_{sea.key}.png)",
                    f"![tracks of every seed](tracks_{sea.key}.png)", ""]


def _spread(criterion: Merit, rows: list[dict]) -> str:
    """'median [25 % - 75 %]' of the rows' values (' of N' for a count), '-' if none."""
    if not rows:
        return "-"
    q1, median, q3 = np.percentile([r[criterion.column] for r in rows], [25, 50, 75])
    total = f" of {rows[0][criterion.out_of]:.0f}" if criterion.out_of else ""
    return (f"{criterion.format(median)} [{criterion.format(q1)} - "
            f"{criterion.format(q3)}]{total}")
