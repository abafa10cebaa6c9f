"""The scorecard: your autopilot beside the paper's PD and sliding-mode ones and the PID, on
the paper's route in calm water and waves, a 40 deg course change, and two wave ensembles on
Dask; each criterion (``merit.CRITERIA``) won or lost on its own, seed-paired against the PD."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from .. import scenarios
from ..analysis.figures import comparison, save
from ..analysis.metrics import heading_error, overshoot, settling_time
from ..analysis.reports import PAPER_TABLES
from ..api import overrides_of
from ..core.files import fresh_folder, write_atomically
from ..core.inprocess import in_process_refusal
from ..core.isolation import Isolation
from ..core.recording import Recording
from ..outputs import Options, run_and_write
from ..scenarios.autopilot import COMPONENT
from .scorecard_report import BASELINE, SEA_NAMES, Sea, change, markdown, pairs
from .campaign import execute
from .spec_file import controller_entry
from .sweep_spec import Spec
from .sweep_figures import distribution, paired_figure, tracks
from .merit import CRITERIA, run_metrics
from .sweep_task import BATCH

BASELINES = {"PD": "pd", "SMC": "smc", "PID": "pid"}   # display name: scenarios <sea>_<suffix>
COURSE_CHANGE = math.radians(40.0)
COURSE_CHANGE_ROUTE = f"0,0;1000,{1000 * math.tan(COURSE_CHANGE)!r}"   # one long leg at 40 deg
COURSE_CHANGE_LEG = math.hypot(1000.0, 1000 * math.tan(COURSE_CHANGE))   # m
COURSE_CHANGE_TIME = 300.0
SETTLING_BAND = 0.02 * COURSE_CHANGE
# Ensembles where the paper's PD and SMC differ (docs/own_autopilot.md: WMO sea state 4, which
# puts every rudder on its stops, did not tell them apart)
SEAS = (Sea("waves", "the paper's waves", "Hs 5 mm, T0 0.8 s"),
        Sea("wind_current", "wind and current", "the paper's waves; 0.05 m/s current (0.42 "
            "m/s at full scale) and a 0.6 m/s gusty wind (5 m/s), both towards east",
            "waves_pd_wind", (("environment.V_c_mean", 0.05), ("environment.beta_c_mean",
                                                                math.pi / 2),
                              ("environment.sigma_V", 0.005), ("environment.T_c", 120.0))),
        Sea("pump_failure", "a steering-gear pump failure", "the paper's waves; one of the "
            "two pumps fails at 150 s, the rudder moves at 10 deg/s", events="pump_failure"))


@dataclass(frozen=True)
class Contender:
    """A controller of the scorecard: the project's (``suffix``) or the user's (``fmu``)."""

    name: str
    suffix: str = "pd"
    fmu: Path | None = None
    port_map: dict[str, str] | None = None
    settings: dict[str, Any] | None = None   # --set values, for the user's autopilot only

    @property
    def paper_cost(self) -> str:
        """J calm / waves in the paper, for one of its controllers; '-' for any other."""
        if self.fmu is not None or f"calm_{self.suffix}" not in PAPER_TABLES:
            return "-"
        return " / ".join(f"{PAPER_TABLES[f'{sea}_{self.suffix}'][2]:.1f}"
                          for sea in ("calm", "waves"))


def course_change(run: Recording) -> dict[str, float]:
    """``run_metrics``, settling_time (s, inf if never settled) and overshoot (rad)."""
    psi = run["ship.psi"]
    error = heading_error(run["guidance.psi_d"], psi)
    return {**run_metrics(run), "settling_time": settling_time(run.t, error, SETTLING_BAND),
            "overshoot": overshoot(psi, psi[0], psi[0] + COURSE_CHANGE)}


def score(fmu: Path, name: str, out: Path, seeds: int = 20, port_map: dict | None = None,
          settings: dict[str, Any] | None = None, workers: int | None = None,
          scheduler: str | None = None,
          progress: Callable[[str], None] = lambda step: None, backend: str = "fmi",
          isolation: Isolation = Isolation("foreign")) -> str:
    """out/scorecard.md of ``fmu`` (called ``name``) and its figures; the markdown. A failed
    run is reported and the scorecard goes on. On "batch" the single runs run in-process."""
    contenders = _contenders(fmu, name, port_map, settings)
    failures: dict[tuple[str, str], str] = {}

    def tested(test: str, label: str, title: str, sea: str, stop_time: float | None = None,
               route: str | None = None) -> dict[str, Recording]:
        """Each contender's run, written to out/runs/<label>_<name>.*, and their figure."""
        runs = {}
        (out / "runs").mkdir(parents=True, exist_ok=True)
        for c in contenders:
            progress(f"{test}, {c.name}")
            settings = dict(c.settings or {})
            if route is not None:
                settings["guidance.waypoints"] = route
            recording = run_and_write(
                scenarios.load(f"{sea}_{c.suffix}", c.fmu, c.port_map), f"{label}_{c.name}",
                out / "runs", overrides_of(settings), Options(
                    stop_time=stop_time, backend="inprocess" if backend == BATCH else backend,
                    plot=False, isolation=isolation)).recording
            if recording.error:
                failures[c.name, test] = recording.error.splitlines()[0]
            else:
                runs[c.name] = recording
        save(comparison(runs, title), out / f"{label}.png")
        return runs

    route = {sea: tested(words, f"route_{sea}", f"The paper's route in {words}",
                         sea=sea) for sea, words in SEA_NAMES.items()}
    changes = {n: course_change(r) for n, r in tested(
        "course change", "course_change", "40 deg course change from straight running, calm "
        "water", sea="calm", stop_time=COURSE_CHANGE_TIME, route=COURSE_CHANGE_ROUTE).items()}
    ensembles = {}
    for sea in SEAS:            # each in a fresh folder, with its figures
        progress(f"wave ensemble in {sea.name}, {seeds} seeds on Dask")
        spec = _ensemble(contenders, seeds, out, sea)
        with fresh_folder(out / ("ensemble" if sea is SEAS[0] else f"ensemble_{sea.key}")) \
                as folder:
            rows = ensembles[sea] = execute(spec, folder, scheduler=scheduler, workers=workers,
                                            progress=False, backend=backend,
                                            isolation=isolation)
        distribution(spec, rows, out / f"criteria_{sea.key}.png", CRITERIA)
        paired_figure(f"The route in {sea.name}", {
            criterion: {c.name: change(criterion, *pairs(criterion, rows, c.name))
                        for c in contenders if c.name != BASELINE}
            for criterion in CRITERIA}, BASELINE, out / f"paired_{sea.key}.png")
        tracks(spec, rows, out / f"tracks_{sea.key}.png")
    isolated = isolation.isolates(COMPONENT, foreign=in_process_refusal(fmu) is not None)
    text = markdown(fmu, name, seeds, {c.name: c.paper_cost for c in contenders}, route,
                    changes, (COURSE_CHANGE_TIME, COURSE_CHANGE_LEG), failures, ensembles,
                    isolated)
    write_atomically(out / "scorecard.md", lambda path: path.write_text(text))
    return text


def _contenders(fmu: Path, name: str, port_map: dict | None,
                settings: dict[str, Any] | None) -> list[Contender]:
    return [*(Contender(label, suffix) for label, suffix in BASELINES.items()),
            Contender(name, fmu=fmu, port_map=port_map, settings=settings)]


def _ensemble(contenders: list[Contender], seeds: int, out: Path, sea: Sea = SEAS[0]) -> Spec:
    """Every contender on the paper's route in ``sea``, over ``seeds`` wave seeds."""
    entries = {c.name: _entry(c, sea) for c in contenders}
    axes: dict[str, list] = {"wave_seed": list(range(1, seeds + 1))}
    return Spec(name=f"ensemble in {sea.name}", axes=axes,
                controllers={n: controller_entry(e, out / "scorecard", n)
                             for n, e in entries.items()}, tracks={})   # every track


def _entry(c: Contender, sea: Sea) -> dict[str, Any]:
    """A contender's sweep entry in ``sea``: its own scenario in the paper's waves, else its
    autopilot put into ``sea.scenario`` with the parameters its own scenario gives it."""
    events = {} if sea.events is None else {"events": sea.events}
    if c.fmu is None and sea.scenario == "waves":
        return {"scenario": f"waves_{c.suffix}", **events}
    scenario = "waves_pd" if sea.scenario == "waves" else sea.scenario
    if c.fmu is not None:
        return {"scenario": scenario, "autopilot": str(c.fmu), "map": c.port_map or {},
                "set": {**(c.settings or {}), **dict(sea.sets)}, **events}
    own = scenarios.load(f"waves_{c.suffix}")
    autopilot = own.components[COMPONENT]
    return {"scenario": scenario, "autopilot": str(own.fmu_path(COMPONENT)), "set": {
        **{f"{COMPONENT}.{k}": v for k, v in autopilot.parameters.items()}, **dict(sea.sets)},
        **events}


def backend_notes(fmu: Path, name: str, port_map: dict | None, backend: str) -> list[str]:
    """``Spec.backend_notes`` of the scorecard's ensembles on ``backend``."""
    spec = _ensemble(_contenders(fmu, name, port_map, None), 1, fmu.parent)
    return spec.backend_notes(backend)
