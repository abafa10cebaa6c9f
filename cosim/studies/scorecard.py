"""The scorecard: your autopilot beside the paper's PD and sliding-mode ones and the PID.

Three tests, the same for every controller:

- **the paper's four runs**: its route in calm water and in waves (Tables 1-2), the
  cost of eq (19);
- **a course change**: 40 deg from steady straight running in calm water, 300 s:
  settling time to 2 % (0.8 deg), overshoot, rudder reversals per minute;
- **a wave ensemble**: the route in waves over N wave seeds, on Dask through the
  sweep machinery (``cosim.studies.sweep``): J per seed, its spread, and seed-paired
  wins against the PD.

``score`` runs them, writes scorecard.md and the figures, and returns the markdown.
"""
from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..analysis.cost import Cost, cost
from ..analysis.figures import comparison_figure
from ..analysis.metrics import heading_error, overshoot, settling_time, sign_reversals_per_minute
from ..analysis.reports import PAPER_TABLES
from ..api import simulate
from ..core.recording import Recording
from .sweep import Spec, comparison, controller_entry, execute
from .sweep_figures import distribution

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

    def run(self, sea: str, **kwargs) -> Recording:
        return simulate(f"{sea}_{self.suffix}", autopilot=self.fmu, port_map=self.port_map,
                        **kwargs)


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
          workers: int | None = None, progress: Callable[[str], None] = lambda step: None
          ) -> str:
    """Run the scorecard of ``fmu`` (called ``name``), write out/scorecard.md and figures."""
    contenders = [*(Contender(label, suffix) for label, suffix in BASELINES.items()),
                  Contender(name, fmu=fmu, port_map=port_map)]
    paper: dict[tuple[str, str], Cost] = {}
    for sea in ("calm", "waves"):
        runs = {}
        for contender in contenders:
            progress(f"{sea} water, {contender.name}")
            runs[contender.name] = contender.run(sea)
            paper[contender.name, sea] = cost(runs[contender.name])
        comparison_figure(runs, out / f"route_{sea}.png",
                          f"The paper's route in {'calm water' if sea == 'calm' else 'waves'}")
    changes, runs = {}, {}
    for contender in contenders:
        progress(f"course change, {contender.name}")
        runs[contender.name] = contender.run("calm", stop_time=COURSE_CHANGE_TIME,
                                             set={"guidance.waypoints": COURSE_CHANGE_ROUTE})
        changes[contender.name] = course_change(runs[contender.name])
    comparison_figure(runs, out / "course_change.png",
                      "40 deg course change from straight running, calm water")
    progress(f"wave ensemble, {seeds} seeds on Dask")
    ensemble = out / "ensemble"
    shutil.rmtree(ensemble, ignore_errors=True)          # a fresh ensemble every time
    ensemble.mkdir(parents=True)
    entries = {c.name: ({"scenario": f"waves_{c.suffix}"} if c.fmu is None else
                        {"autopilot": str(c.fmu), "map": c.port_map or {}})
               for c in contenders}
    spec = Spec(name="ensemble", axes={"wave_seed": list(range(1, seeds + 1))},
                controllers={n: controller_entry(e, out / "scorecard", n)
                             for n, e in entries.items()})
    rows = execute(spec, ensemble, workers=workers, progress=False)
    distribution(spec, rows, out / "J_distribution.png")
    text = _markdown(fmu, name, seeds, contenders, paper, changes, spec, rows)
    (out / "scorecard.md").write_text(text)
    return text


def _markdown(fmu: Path, name: str, seeds: int, contenders: list[Contender],
              paper: dict[tuple[str, str], Cost], changes: dict[str, CourseChange],
              spec: Spec, rows: list[dict]) -> str:
    lines = [f"# Scorecard: {name}", "",
             f"Autopilot `{fmu}` beside the paper's PD and sliding-mode (SMC) autopilots and "
             "the project's PID, on CyberShip II (docs/own_autopilot.md says how each is run).",
             "", "## The paper's route (Tables 1-2, eq 19; lower is better)", "",
             "| controller | calm psi_E | calm delta_E | calm J | waves psi_E | waves delta_E "
             "| waves J | paper J calm / waves |", "|---|---|---|---|---|---|---|---|"]
    for c in contenders:
        calm, waves = paper[c.name, "calm"], paper[c.name, "waves"]
        theirs = (f"{PAPER_TABLES[f'calm_{c.suffix}'][2]:.1f} / "
                  f"{PAPER_TABLES[f'waves_{c.suffix}'][2]:.1f}"
                  if c.fmu is None and f"calm_{c.suffix}" in PAPER_TABLES else "-")
        lines.append(f"| {c.name} | {calm.psi_E:.1f} | {calm.delta_E:.1f} | {calm.J:.1f} | "
                     f"{waves.psi_E:.1f} | {waves.delta_E:.1f} | {waves.J:.1f} | {theirs} |")
    lines += ["", "![route in calm water](route_calm.png)", "![route in waves](route_waves.png)",
              "", f"## A 40 deg course change, calm water, {COURSE_CHANGE_TIME:.0f} s", "",
              "| controller | settling time to 2 % (s) | overshoot (deg) | rudder reversals "
              "per min | max rudder (deg) |", "|---|---|---|---|---|"]
    for c in contenders:
        r = changes[c.name]
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
        lines += ["", f"{len(failed)} runs failed; the first: "
                      f"`{failed[0]['error'].splitlines()[0][:200]}`"]
    lines += ["", "Seed-paired against the PD (a win: lower J on the same sea):", "",
              comparison(spec, rows, baseline="PD"), "",
              "![J per controller](J_distribution.png)", ""]
    return "\n".join(lines)
