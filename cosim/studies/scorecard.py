"""The scorecard: your autopilot beside the paper's PD and sliding-mode ones and the PID.

Three tests, the same for every controller:

- **the paper's four runs**: its route in calm water and in waves (Tables 1-2), the
  cost of eq (19);
- **a course change**: 40 deg from steady straight running in calm water, 300 s:
  settling time to 2 % (0.8 deg), overshoot, rudder reversals per minute;
- **a wave ensemble**: the route in waves over N wave seeds, on Dask through the
  sweep machinery (``cosim.studies.sweep``): J per seed, its spread, and seed-paired
  wins against the PD.

``score`` runs them, writes scorecard.md and the figures, and each run's CSV and
metadata in runs/ (through ``cosim.outputs``, as ``cosim.run`` does), and returns the
markdown.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..analysis.cost import Cost, cost
from ..analysis.figures import comparison_figure
from ..analysis.metrics import heading_error, overshoot, settling_time, sign_reversals_per_minute
from ..analysis.reports import PAPER_TABLES
from .. import scenarios
from ..api import SimulationError, overrides_of
from ..core.files import fresh_folder, write_atomically
from ..core.recording import Recording
from ..outputs import Options, run_and_write
from .sweep import Spec, comparison, controller_entry, execute
from .sweep_figures import distribution, tracks

BASELINES = {"PD": "pd", "SMC": "smc", "PID": "pid"}
"""The project's autopilots by display name: scenarios <sea>_<suffix>."""
COURSE_CHANGE = math.radians(40.0)
COURSE_CHANGE_ROUTE = f"0,0;1000,{1000 * math.tan(COURSE_CHANGE)!r}"
"""One long leg at 40 deg: the ship, heading north at t = 0, turns onto it."""
COURSE_CHANGE_TIME = 300.0
SETTLING_BAND = 0.02 * COURSE_CHANGE


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
class CourseChange:
    settling_time: float          # s, inf if it never settles within the run
    overshoot: float              # rad
    reversals_per_min: float
    max_delta: float              # rad


def course_change(run: Recording) -> CourseChange:
    """Figures of merit of the 40 deg course change."""
    t, psi, delta = run.t, run["ship.psi"], run["ship.delta"]
    error = heading_error(run["guidance.psi_d"], psi)
    return CourseChange(settling_time(t, error, SETTLING_BAND),
                        overshoot(psi, psi[0], psi[0] + COURSE_CHANGE),
                        sign_reversals_per_minute(t, delta), float(np.abs(delta).max()))


def score(fmu: Path, name: str, out: Path, seeds: int = 20, port_map: dict | None = None,
          settings: dict[str, Any] | None = None, workers: int | None = None,
          scheduler: str | None = None,
          progress: Callable[[str], None] = lambda step: None, backend: str = "fmi") -> str:
    """Run the scorecard of ``fmu`` (called ``name``), write out/scorecard.md and figures.

    A run that fails (an FMU error) is reported in the tables as failed, with its message,
    and the scorecard goes on. ``backend="inprocess"`` runs this project's FMUs without
    FMI (the same results, faster); ``fmu`` then still runs through FMI unless it is one
    of ours (``cosim.core.inprocess.in_process_refusal``).
    """
    contenders = _contenders(fmu, name, port_map, settings)
    failures: dict[tuple[str, str], str] = {}

    def attempt(contender: Contender, test: str, label: str, **kwargs) -> Recording | None:
        progress(f"{test}, {contender.name}")
        try:
            return contender.run(label, out / "runs", **kwargs, backend=backend)
        except SimulationError as error:
            failures[contender.name, test] = str(error).splitlines()[0]
            return None

    paper: dict[tuple[str, str], Cost] = {}
    for sea in ("calm", "waves"):
        runs = {c.name: attempt(c, f"{sea} water", f"route_{sea}", sea=sea)
                for c in contenders}
        runs = {n: r for n, r in runs.items() if r is not None}
        paper.update({(n, sea): cost(r) for n, r in runs.items()})
        comparison_figure(runs, out / f"route_{sea}.png",
                          f"The paper's route in {'calm water' if sea == 'calm' else 'waves'}")
    runs = {c.name: attempt(c, "course change", "course_change", sea="calm",
                            stop_time=COURSE_CHANGE_TIME, route=COURSE_CHANGE_ROUTE)
            for c in contenders}
    runs = {n: r for n, r in runs.items() if r is not None}
    changes = {n: course_change(r) for n, r in runs.items()}
    comparison_figure(runs, out / "course_change.png",
                      "40 deg course change from straight running, calm water")
    progress(f"wave ensemble, {seeds} seeds on Dask")
    spec = _ensemble(contenders, seeds, out)
    with fresh_folder(out / "ensemble") as ensemble:     # a fresh ensemble every time
        rows = execute(spec, ensemble, scheduler=scheduler, workers=workers, progress=False,
                       backend=backend)
    distribution(spec, rows, out / "J_distribution.png")
    tracks(spec, rows, out / "tracks_waves.png")
    text = _markdown(fmu, name, seeds, contenders, paper, changes, failures, spec, rows)
    write_atomically(out / "scorecard.md", lambda path: path.write_text(text))
    return text


def _contenders(fmu: Path, name: str, port_map: dict | None,
                settings: dict[str, Any] | None) -> list[Contender]:
    return [*(Contender(label, suffix) for label, suffix in BASELINES.items()),
            Contender(name, fmu=fmu, port_map=port_map, settings=settings)]


def _ensemble(contenders: list[Contender], seeds: int, out: Path) -> Spec:
    """The wave ensemble: every contender on the paper's route in waves, over ``seeds``."""
    entries = {c.name: ({"scenario": f"waves_{c.suffix}"} if c.fmu is None else
                        {"autopilot": str(c.fmu), "map": c.port_map or {},
                         "set": c.settings or {}})
               for c in contenders}
    return Spec(name="ensemble", axes={"wave_seed": list(range(1, seeds + 1))},
                controllers={n: controller_entry(e, out / "scorecard", n)
                             for n, e in entries.items()}, tracks={})   # every track


def backend_notes(fmu: Path, name: str, port_map: dict | None, backend: str) -> list[str]:
    """Which FMUs of the scorecard (the project's and ``fmu``) run through FMI although
    ``backend`` is "inprocess": the ensemble's systems hold every FMU the scorecard runs."""
    return _ensemble(_contenders(fmu, name, port_map, None), 1, fmu.parent).backend_notes(
        backend)


def _markdown(fmu: Path, name: str, seeds: int, contenders: list[Contender],
              paper: dict[tuple[str, str], Cost], changes: dict[str, CourseChange],
              failures: dict[tuple[str, str], str], spec: Spec, rows: list[dict]) -> str:
    lines = [f"# Scorecard: {name}", "",
             f"Autopilot `{fmu}` beside the paper's PD and sliding-mode (SMC) autopilots and "
             "the project's PID, on CyberShip II (docs/own_autopilot.md says how each is run).",
             "", "## The paper's route (Tables 1-2, eq 19; lower is better)", "",
             "| controller | calm psi_E | calm delta_E | calm J | waves psi_E | waves delta_E "
             "| waves J | paper J calm / waves |", "|---|---|---|---|---|---|---|---|"]
    for c in contenders:
        cells = []
        for sea in ("calm", "waves"):
            r = paper.get((c.name, sea))
            cells += ([f"{r.psi_E:.1f}", f"{r.delta_E:.1f}", f"{r.J:.1f}"] if r
                      else ["failed"] * 3)
        theirs = (f"{PAPER_TABLES[f'calm_{c.suffix}'][2]:.1f} / "
                  f"{PAPER_TABLES[f'waves_{c.suffix}'][2]:.1f}"
                  if c.fmu is None and f"calm_{c.suffix}" in PAPER_TABLES else "-")
        lines.append(f"| {c.name} | {' | '.join(cells)} | {theirs} |")
    lines += ["", "![route in calm water](route_calm.png)", "![route in waves](route_waves.png)",
              "", f"## A 40 deg course change, calm water, {COURSE_CHANGE_TIME:.0f} s", "",
              "| controller | settling time to 2 % (s) | overshoot (deg) | rudder reversals "
              "per min | max rudder (deg) |", "|---|---|---|---|---|"]
    for c in contenders:
        r = changes.get(c.name)
        if r is None:
            lines.append(f"| {c.name} | failed | failed | failed | failed |")
            continue
        settled = f"{r.settling_time:.1f}" if math.isfinite(r.settling_time) else \
            f"> {COURSE_CHANGE_TIME:.0f}"
        lines.append(f"| {c.name} | {settled} | {math.degrees(r.overshoot):.2f} | "
                     f"{r.reversals_per_min:.1f} | {math.degrees(r.max_delta):.1f} |")
    ok = [r for r in rows if r["status"] == "ok"]
    lines += ["", "![course change](course_change.png)", "",
              f"## Wave ensemble: the route in waves, {seeds} wave seeds (Hs 5 mm, T0 0.8 s)",
              "", "| controller | J median | J mean | J 5-95 % | runs ok |", "|---|---|---|---|---|"]
    for c in contenders:
        J = np.array([r["J"] for r in ok if r["controller"] == c.name])
        spread = (f"{np.median(J):.1f} | {J.mean():.1f} | {np.percentile(J, 5):.1f} - "
                  f"{np.percentile(J, 95):.1f}") if J.size else "- | - | -"
        lines.append(f"| {c.name} | {spread} | {J.size}/{seeds} |")
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        lines += ["", f"{len(failed)} runs of the ensemble failed; the first: "
                      f"`{failed[0]['error'].splitlines()[0][:200]}`"]
    if failures:
        lines += ["", "Runs that failed:", ""]
        lines += [f"- {name}, {test}: `{message[:200]}`"
                  for (name, test), message in failures.items()]
    lines += ["", "Seed-paired against the PD (a win: lower J on the same sea):", "",
              comparison(spec, rows, baseline="PD"), "",
              "![J per controller](J_distribution.png)",
              "![tracks of every seed](tracks_waves.png)", ""]
    return "\n".join(lines)
