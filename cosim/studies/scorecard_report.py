"""What a scorecard says: each controller against the PD seed by seed, and scorecard.md."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis.metrics import LAMBDA, RUDDER_DEADBAND, route_completion
from ..core.recording import Recording
from . import table
from .merit import CRITERIA, Merit, route_of, run_metrics
from .sweep_figures import STATISTICS

BASELINE = "PD"                 # every other controller is paired with it, seed by seed
TIE = 0.01                      # values closer than this share of the baseline's tie
SEA_NAMES = {"calm": "calm water", "waves": "waves"}      # the single runs' seas


@dataclass(frozen=True)
class Sea:
    """The conditions of an ensemble: the paper's waves, or ``scenario`` (each autopilot put
    into it) with ``sets`` and timed ``events``; the wave seed varies."""

    key: str                             # in file names: ensemble_<key>, criteria_<key>.png
    name: str
    detail: str                          # what makes it
    scenario: str = "waves"              # "waves": each controller's own waves_<suffix>
    sets: tuple[tuple[str, float], ...] = ()
    events: str | None = None


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
        """even: every seed tied; better (worse): no seed lost (won), or more than half won
        (lost); else mixed. A one-sided record is never even."""
        if not self.losses:
            return "better" if self.wins else "even"
        if not self.wins or 2 * self.losses > self.seeds:
            return "worse"
        return "better" if 2 * self.wins > self.seeds else "mixed"


def pairs(criterion: Merit, rows: list[dict], controller: str,
          baseline: str = BASELINE) -> tuple[np.ndarray, np.ndarray]:
    """(controller's, baseline's) values of ``criterion`` on the seeds both ran ok."""
    values = {name: {r["wave_seed"]: r[criterion.column] for r in _ok(rows, name)}
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
    """A win is the better value on the same sea by more than ``TIE`` of the baseline's."""
    mine, base = pairs(criterion, rows, controller, baseline)
    margin = (1.0 if criterion.lower_is_better else -1.0) * (base - mine)   # > 0: mine better
    tied = np.abs(margin) <= TIE * np.abs(base)
    changes = change(criterion, mine, base)
    return Paired(int(np.sum((margin > 0) & ~tied)), int(np.sum((margin < 0) & ~tied)),
                  int(np.sum(tied)), float(np.median(changes)) if changes.size else math.nan)


def markdown(fmu: Path, name: str, seeds: int, paper: dict[str, str],
             route: dict[str, dict[str, Recording]], changes: dict[str, dict],
             course: tuple[float, float], failures: dict[tuple[str, str], str],
             ensembles: dict[Sea, list[dict]], isolated: bool = False) -> str:
    """scorecard.md: ``paper`` gives each controller's J calm / waves in the paper ('-');
    ``course`` the course change's duration (s) and leg (m); ``isolated``: how ``fmu`` ran."""
    names = list(paper)
    metrics = {sea: {n: run_metrics(run) for n, run in runs.items()} for sea, runs in route.items()}
    lines = [f"# Scorecard: {name}", "",
             f"Autopilot `{fmu}` beside the paper's PD and sliding-mode (SMC) autopilots and "
             "the project's PID, on CyberShip II (docs/own_autopilot.md says how each is run).",
             "Each criterion is scored on its own, with its unit and the side that is better; "
             "there is no overall rank. Angles in degrees, distances in m; a waypoint is "
             "reached when the ship comes within the guidance's circle of acceptance of it "
             "(waypoints are numbered from 1, the start); a rudder reversal is a crossing "
             "from one side to the other, counted once the rudder is "
             f"{math.degrees(RUDDER_DEADBAND):g} deg past amidships on the new side.", "",
             f"`{fmu.name}` ran " + ("in a process of its own (isolated): a crash, exit or hang "
                                     "in it failed only its own runs, listed below if any." if
                                     isolated else "in the scorecard's processes (not "
                                     "isolated)."), ""]
    lines += _at_a_glance(names, metrics, ensembles, seeds)
    lines += _paper_route(paper, route, metrics)
    lines += _course_change(names, changes, *course)
    for sea, rows in ensembles.items():
        lines += _ensemble_section(sea, names, seeds, rows)
    if failures:
        lines += ["## Runs that failed", "", *(f"- {who}, {test}: `{message[:200]}`"
                                               for (who, test), message in failures.items()),
                  ""]
    return "\n".join(lines)


def _label(criterion: Merit, better: bool = False) -> str:
    """The criterion's label (unit), and with ``better`` the side that is better."""
    unit = f" ({criterion.unit})" if criterion.unit else ""
    return criterion.label + unit + (f", {criterion.better}" if better else "")


def _of(criterion: Merit, row: dict) -> str:
    """' of N' for a count out of a total, '' for any other criterion."""
    return f" of {row[criterion.out_of]:.0f}" if criterion.out_of else ""


def _reached(m: dict) -> str:
    """'reached 3 of 4 waypoints, the last included' of a run's ``run_metrics``."""
    last = "the last included" if m["last_waypoint_reached"] else "**not** the last"
    return f"{_waypoints_reached([m])}, {last}"


def _ok(rows: list[dict], name: str) -> list[dict]:
    return [r for r in rows if r["status"] == "ok" and r["controller"] == name]


def _at_a_glance(names: list[str], metrics: dict[str, dict[str, dict]],
                 ensembles: dict[Sea, list[dict]], seeds: int) -> list[str]:
    """Each controller's verdicts against the PD per ensemble, and route completion."""
    lines = [f"## At a glance: each controller against the {BASELINE}", "",
             f"Seed-paired over {seeds} wave seeds: **better** (**worse**) means better "
             f"(worse) than the {BASELINE} on the same sea in more than half of the seeds, or "
             "on some and worse (better) on none, the others tied (within "
             f"{100 * TIE:g} % of the {BASELINE}'s value); *even* that every seed is a tie, "
             "*mixed* neither; then the seeds won, lost and tied of those both ran, and the "
             f"median paired ratio to the {BASELINE} or difference from it.", ""]
    for sea, rows in ensembles.items():
        apart = sum(paired(c, rows, "SMC").verdict != "even" for c in CRITERIA)
        lines += [f"The route in {sea.name} ({sea.detail}):", "", *table(
            ["criterion", "better", *names[1:]],
            ([_label(c), c.better.split()[0], *(_verdict(c, paired(c, rows, name))
                                                for name in names[1:])] for c in CRITERIA)),
            "", f"The paper's own controllers, SMC against PD, differ here on {apart} of "
                f"{len(CRITERIA)} criteria" + ("." if apart else ": this ensemble does not "
                                               "tell them apart."), ""]
    lines += ["Route completion (higher is better):", "", *table(
        ["controller", *SEA_NAMES.values(), *(f"ensemble, {sea.name}" for sea in ensembles)],
        ([name, *(_reached(metrics[sea][name]) if name in metrics[sea] else "failed"
                  for sea in SEA_NAMES),
          *(_ensemble_completion(_ok(rows, name)) for rows in ensembles.values())]
         for name in names)), ""]
    for sea, rows in ensembles.items():
        for name in names:                  # a plain sentence for a route never finished
            ok = _ok(rows, name)
            if ok and not any(r["last_waypoint_reached"] == 1.0 for r in ok):
                stops = np.median([r["at_stops_pct"] for r in ok])
                held = (f", the rudder on its stops a median {stops:.0f} % of the run"
                        if stops else "")
                lines.append(f"- In {sea.name}, **{name} never reached the last waypoint** "
                             f"in any of {len(ok)} seeds: it {_waypoints_reached(ok)}{held}.")
    return lines + [""]


def _ensemble_completion(ok: list[dict]) -> str:
    if not ok:
        return "no run ok"
    last = sum(r["last_waypoint_reached"] == 1.0 for r in ok)
    return f"{_waypoints_reached(ok)}; the last in {last} of {len(ok)} seeds"


def _verdict(criterion: Merit, p: Paired) -> str:
    """'**better**: won 18, lost 2, tied 0 of 20; median ratio 0.13'."""
    if not p.seeds:
        return "no seed ran for both"
    word = f"**{p.verdict}**" if p.verdict in ("better", "worse") else f"*{p.verdict}*"
    if criterion.paired == "ratio":
        median = f"median ratio {p.median:.2f}" if math.isfinite(p.median) else "no ratio"
    else:
        unit = {"": "", "%": " percentage points"}.get(criterion.unit, f" {criterion.unit}")
        median = f"median difference {criterion.format(p.median, '+')}{unit}"
    return f"{word}: won {p.wins}, lost {p.losses}, tied {p.ties} of {p.seeds}; {median}"


def _waypoints_reached(ok: list[dict]) -> str:
    """'reached 3 of 4 waypoints' over runs that ran ok: the count, or its median and range."""
    reached = np.array([r["waypoints_reached"] for r in ok])
    spread = (f"{reached.min():.0f}" if reached.min() == reached.max() else
              f"a median {np.median(reached):g} (from {reached.min():.0f} to "
              f"{reached.max():.0f})")
    return f"reached {spread} of {ok[0]['waypoints']:.0f} waypoints"


def _paper_route(paper: dict[str, str], route: dict[str, dict[str, Recording]],
                 metrics: dict[str, dict[str, dict]]) -> list[str]:
    def cost(m: dict | None) -> list[str]:          # psi_E, delta_E and J of eq (19)
        if m is None:
            return ["failed"] * 3
        return [f"{m['psi_E']:.1f}", f"{LAMBDA * m['sum_delta2']:.1f}", f"{m['J']:.1f}"]
    lines = ["## The paper's route (Tables 1-2, eq 19; lower is better)", "", *table(
        ["controller", "calm psi_E", "calm delta_E", "calm J", "waves psi_E", "waves delta_E",
         "waves J", "paper J calm / waves"],
        ([name, *cost(metrics["calm"].get(name)), *cost(metrics["waves"].get(name)), theirs]
         for name, theirs in paper.items())),
        "", "Every criterion, one run each (the scenarios' wave seed):", "",
        *table(["controller", "sea", *(_label(c, better=True) for c in CRITERIA)],
               ([name, sea, *(c.format(row[c.column]) + _of(c, row) for c in CRITERIA)]
                for sea, rows in metrics.items() for name, row in rows.items())), ""]
    for sea, rows in metrics.items():
        for name, m in rows.items():
            if m["waypoints_reached"] < m["waypoints"]:
                run = route[sea][name]
                done = route_completion(run["ship.x"], run["ship.y"], *route_of(run))
                missed = ", ".join(f"waypoint {k} ({x:g}, {y:g}) by {d:.1f} m"
                                   for k, ((x, y), d, hit) in enumerate(
                                       zip(done.points, done.closest, done.reached), start=1)
                                   if not hit)
                lines.append(f"- {name}, {sea}: {_reached(m)}; missed {missed} "
                             f"(circle of acceptance {done.R_accept:g} m)")
    return lines + ["", "![route in calm water](route_calm.png)",
                    "![route in waves](route_waves.png)", ""]


def _course_change(names: list[str], changes: dict[str, dict], time: float,
                   leg: float) -> list[str]:
    def cells(m: dict | None) -> list[str]:
        if m is None:
            return ["failed"] * 6
        settled = (f"{m['settling_time']:.1f}" if math.isfinite(m["settling_time"])
                   else f"> {time:.0f}")
        return [settled, f"{math.degrees(m['overshoot']):.2f}", f"{m['reversals_per_min']:.1f}",
                f"{m['mean_rudder_rate_deg_s']:.2f}", f"{m['max_delta_deg']:.1f}",
                f"{m['cross_track_max_m']:.2f}"]
    return [f"## A 40 deg course change, calm water, {time:.0f} s (lower is better)", "",
            *table(["controller", "settling time to 2 % (s)", "overshoot (deg)",
                    "rudder reversals (1/min)", "mean abs rudder rate (deg/s)",
                    "max rudder (deg)", "max cross-track (m)"],
                   ([name, *cells(changes.get(name))] for name in names)),
            "", f"The course change follows one leg of {leg:.0f} m, longer than the ship "
                f"sails in {time:.0f} s: route completion does not apply to it.",
            "", "![course change](course_change.png)", ""]


def _ensemble_section(sea: Sea, names: list[str], seeds: int, rows: list[dict]) -> list[str]:
    """Each criterion's median and IQR per controller."""
    ok = {name: _ok(rows, name) for name in names}
    lines = [f"## Wave ensemble: the route in {sea.name} ({sea.detail}), {seeds} wave seeds",
             "", "Each criterion: median [IQR, 25-75 %] over the seeds that ran; waypoints "
             "reached out of the route's.", "",
             *table(["controller", "runs ok", *(_label(c, better=True) for c in CRITERIA)],
                    ([name, f"{len(ok[name])}/{seeds}", *(_spread(c, ok[name]) for c in CRITERIA)]
                     for name in names))]
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
    q1, median, q3 = map(criterion.format, np.percentile([r[criterion.column] for r in rows],
                                                         [25, 50, 75]))
    return f"{median} [{q1} - {q3}]{_of(criterion, rows[0])}"


def result_card(recording: Recording, files: list[Path]) -> str:
    """Every criterion of one run read from another tool's result ``files``."""
    m, (points, R_accept) = run_metrics(recording), route_of(recording)
    route = " ".join(f"({x:g},{y:g})" for x, y in points)
    return "\n".join([f"# Criteria of {', '.join(f.name for f in files)}", "",
                      f"Route {route} m, circle of acceptance {R_accept:g} m; "
                      f"{len(recording.t)} samples.", "",
                      *table(["criterion", "value", "better"],
                             ([_label(c), c.format(m[c.column]) + _of(c, m), c.better]
                              for c in CRITERIA)), ""])
