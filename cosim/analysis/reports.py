"""What ``cosim.run`` prints for a run: what it was, from the parameter values the FMUs held
(never typed per scenario); eq (19) or the IMO figures; the paper's Tables 1-2 beside ours."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from autopilot_fmu.guidance import route as followed_route
from ship_fmu.data import Hull

from ..core.recording import Recording
from ..scenarios import SCENARIO_DIR
from .manoeuvres import (STANDARD, Assessment, Criterion, TurningCircle, ZigZagResult,
                         turning_circle_of, zigzag_of)
from .metrics import (LAMBDA, RUDDER_DEADBAND, Cost, at_stops, cost,
                      rudder_reversals_per_minute)
from .seastate import SCALE

PAPER_TABLES = {   # Tomera (2010), Tables 1 and 2: psi_E, delta_E, J
    "calm_pd": (128.20, 128.74, 256.94), "calm_smc": (117.07, 117.42, 234.49),
    "waves_pd": (259.38, 261.40, 520.78), "waves_smc": (194.57, 195.98, 390.55),
}


def course_keeping_report(recording: Recording, lam: float = LAMBDA, **_) -> list[str]:
    c = cost(recording, lam)
    t, delta = recording.t, recording["ship.delta"]
    stops = recording.meta.get("parameters", {}).get("ship", {}).get("delta_max", math.inf)
    pinned = at_stops(delta, stops)
    warning = ([f"warning: the rudder was at its stops for {100 * pinned.mean():.0f} % of the "
                f"run (from t = {t[pinned][0]:.0f} s): the autopilot could not hold the course"]
               if pinned.mean() > 0.1 else [])
    return warning + [f"psi_E = {c.psi_E:.2f} rad^2   sum delta^2 = {c.sum_delta2:.3f} rad^2   "
            f"lambda = {c.lam:.4f}   delta_E = {c.delta_E:.2f}   J = {c.J:.2f}",
            "(eq 19: J = psi_E + delta_E; psi_E sums the squared heading errors, delta_E = "
            "lambda sum delta^2, lambda making them equal on calm_pd; over the 0.1 s samples)",
            f"rudder: max |delta| = {math.degrees(abs(delta).max()):.1f} deg, "
            f"{rudder_reversals_per_minute(t, delta):.1f} reversals per minute (crossings beyond "
            f"+-{math.degrees(RUDDER_DEADBAND):g} deg)"]


def criterion_text(c: Criterion) -> str:
    value = c.missing if math.isnan(c.value) else _amount(c.value, c.unit)
    if c.at_least:
        value = f"at least {value}, the turn unchecked at the end of the run"
    basis = f"; {c.basis}" if c.basis else ""
    return (f"{c.verdict}  {c.figure} {value} (limit {_amount(c.limit, c.unit)}; {STANDARD} "
            f"{c.clause}{basis})")


def _amount(x: float, unit: str) -> str:
    return f"{math.degrees(x):.1f} deg" if unit == "rad" else f"{x:.2f} L"


def _judged(a: Assessment) -> list[str]:
    """The criteria's lines and what they are worth here: the standard's ships, this scale."""
    if not a.criteria:
        return [f"no {STANDARD} criterion applies: it judges the 35 deg turning circle and "
                "the 10/10 and 20/20 zig-zags"]
    return [*map(criterion_text, a.criteria),
            f"{STANDARD} is written for ships of 100 m and over; CyberShip II is a 1:{SCALE:g} "
            f"model ({Hull.L * SCALE:.0f} m at full scale): its criteria apply here through "
            "Froude scaling, as an indication"]


def _turning_figures(tc: TurningCircle, L: float) -> str:
    short = f"the heading changed by only {math.degrees(tc.heading_change):.0f} deg in the run"
    if math.isnan(tc.advance):
        return f"{short}: no advance, transfer or tactical diameter (at 90 and 180 deg)"
    at_90 = (f"advance {tc.advance:.3f} m ({tc.advance / L:.2f} L), transfer "
             f"{tc.transfer:.3f} m ({tc.transfer / L:.2f} L) at 90 deg heading change")
    if math.isnan(tc.tactical_diameter):
        return f"{at_90}; {short}: no tactical diameter (at 180 deg)"
    return (f"{at_90}; tactical diameter {tc.tactical_diameter:.3f} m "
            f"({tc.tactical_diameter / L:.2f} L) at 180 deg")


def turning_circle_report(recording: Recording, **_) -> list[str]:
    a = turning_circle_of(recording)
    tc, L = a.figures, Hull.L
    rates = f"2U/|r| = {tc.diameter_from_rates:.3f} m"
    steady = (f"{rates} (the run turned less than 540 deg: no lap to fit)"
              if math.isnan(tc.steady_diameter) else f"{tc.steady_diameter:.3f} m "
              f"({tc.steady_diameter / L:.2f} L, circle fitted to the last lap; {rates})")
    lines = [_turning_figures(tc, L),
             f"steady turn: diameter {steady}, yaw rate "
             f"{math.degrees(tc.steady_yaw_rate):.3f} deg/s, speed {tc.steady_speed:.3f} m/s "
             f"({tc.steady_speed / tc.approach_speed:.0%} of the approach), drift angle "
             f"{math.degrees(tc.drift_angle):.1f} deg"]
    if tc.tactical_diameter < tc.steady_diameter:
        lines.append(f"the tactical diameter is below the steady one because the ship turns "
                     f"with its bow {abs(math.degrees(tc.drift_angle)):.0f} deg inside its track: "
                     f"at 180 deg heading change its course has turned only "
                     f"{math.degrees(tc.course_change_at_tactical):.0f} deg")
    return lines + _judged(a)


def _zigzag_times(zz: ZigZagResult) -> str:
    if len(zz.executes) < 2:
        return "the heading never reached the switching angle"
    times = [f"initial turning time {zz.initial_turning_time:.1f} s (first to second execute, "
             f"{zz.initial_turning_distance / Hull.L:.2f} L travelled)"]
    if zz.overshoots:
        times.append(f"time to check yaw {zz.time_to_check_yaw:.1f} s (second execute to the "
                     f"first overshoot, at t = {zz.overshoots[0].time:.1f} s)")
    if not math.isnan(zz.period):
        times.append(f"period {zz.period:.1f} s (second to fourth execute)")
    return ", ".join(times)


def zigzag_report(recording: Recording, **_) -> list[str]:
    a = zigzag_of(recording)
    zz = a.figures
    measured = [f"{name} overshoot {math.degrees(o.angle):.2f} deg"
                for name, o in zip(("first", "second"), zz.overshoots)]
    lines = [", ".join(measured)] if measured else []
    if zz.running is not None:
        rudder = "counter-rudder" if zz.reversals else "rudder"
        lines.append(f"the turn was never checked: {zz.reversals} rudder reversal(s) of 3 in "
                     f"the run, heading {math.degrees(recording['ship.psi'][-1]):.0f} deg at "
                     f"t = {recording.t[-1]:.0f} s, still turning at "
                     f"{math.degrees(recording['ship.r'][-1]):.1f} deg/s with "
                     f"{math.degrees(a.delta):.0f} deg of {rudder}")
    elif zz.reversals > 0 and not zz.checked:
        lines.append("the run ended before the second overshoot")
    return lines + [_zigzag_times(zz)] + _judged(a)


def _label(sea: str, controller: str) -> str:
    return controller.upper() if f"{sea}_{controller}" in PAPER_TABLES else controller


def tables(costs: dict[tuple[str, str], Cost],
           spreads: dict[tuple[str, str], str] | None = None, spreads_title: str = "") -> str:
    """Tables 1 and 2 of the paper beside ours, ``costs`` by (sea, controller); ``spreads``
    (a perturbation ensemble's word on each row) below, under ``spreads_title``."""
    lines = []
    for caption, sea in (("Table 1, calm water", "calm"), ("Table 2, waves", "waves")):
        lines += [f"{caption}:", f"  {'':16}{'psi_E':>9}{'delta_E':>9}{'J':>9}   |"
                  f"{'paper psi_E':>12}{'delta_E':>9}{'J':>9}"]
        for (row_sea, controller), c in costs.items():
            if row_sea != sea:
                continue
            paper = PAPER_TABLES.get(f"{sea}_{controller}")
            theirs = (f"{paper[0]:12.2f}{paper[1]:9.2f}{paper[2]:9.2f}" if paper
                      else f"{'-':>12}{'-':>9}{'-':>9}")
            name = f"{_label(sea, controller)} controller"
            lines.append(f"  {name:16}{c.psi_E:9.2f}{c.delta_E:9.2f}{c.J:9.2f}   |{theirs}")
    lam = next(iter(costs.values())).lam if costs else LAMBDA
    lines.append(f"  (lambda = {lam:.4f}, delta_E = lambda * sum delta^2; sums over the "
                 "0.1 s samples, rad^2)")
    if spreads:
        lines.append(f"{spreads_title}:")
        lines += [f"  {sea} {_label(sea, controller)}: {text}"
                  for (sea, controller), text in spreads.items()]
    return "\n".join(lines)


def value(x: Any, unit: str = "", degrees: bool = True) -> str:
    """A parameter value, 4 significant digits; angles in degrees if ``degrees``."""
    if isinstance(x, float) and degrees and unit in ("rad", "rad/s"):
        x, unit = x * math.degrees(1.0), unit.replace("rad", "deg")
    text = f"{x:.4g}" if isinstance(x, float) else str(x)
    if len(text) > 60:                  # a network's JSON, say: the JSON file has it all
        text = f"{text[:40]}... ({len(text)} characters)"
    return f"{text} {'' if unit == '1' else unit}".strip()


def overrides(meta: dict[str, Any]) -> str:
    """The settings on top of the scenario, as --set options."""
    return " ".join(f"--set {c}.{n}={x}" for c, values in meta.get("overrides", {}).items()
                    for n, x in values.items())


def _isolated(backends: dict[str, str]) -> str:
    """", isolated: NAMES" (every FMU), or ""."""
    names = [name for name, kind in backends.items() if kind.endswith("isolated")]
    return "" if not names else ", every FMU isolated" if len(names) == len(backends) else \
        f", isolated: {', '.join(names)}"


def conditions(meta: dict[str, Any]) -> list[str]:
    """What a run was, line by line."""
    p, units = meta.get("parameters", {}), meta.get("parameter_units", {})
    lines = []
    if "stop_time" in meta:
        lines.append(f"{meta['stop_time'] - meta['start_time']:g} s in steps of "
                     f"{meta['step_size']:g} s, {meta['coupling']} coupling, "
                     f"{meta['backend']} backend" + _isolated(meta.get("backends") or {}))
    if "guidance" in p:
        try:
            points = " ".join(f"({x:g},{y:g})" for x, y in followed_route(p["guidance"]))
        except ValueError:              # the guidance refuses it: shown as given
            points = repr(p["guidance"].get("waypoints"))
        lines.append(f"route {points} m, acceptance radius {p['guidance']['R_accept']:.3g} m")
    if "ship" in p:
        ship = p["ship"]
        sea = "calm water" if ship.get("Hs", 0.0) == 0.0 else (
            f"waves Hs {ship['Hs'] * 1000:.3g} mm, T0 {ship['T0']:.3g} s, travelling to "
            f"{math.degrees(ship['psi_w']) % 360:.0f} deg, seed {ship['wave_seed']}")
        lines.append(f"{sea}; rudder within +-{math.degrees(ship['delta_max']):.3g} deg at up "
                     f"to {math.degrees(ship['delta_rate_max']):.3g} deg/s; starting at "
                     f"{ship['u0']:.3g} m/s")
    # An autopilot's gains stay in their units (eta_h = 10 rad); a program's angles in deg.
    for component, degrees in (("autopilot", False), ("program", True)):
        if component in p:
            fmu = meta.get("fmus", {}).get(component, {}).get("file", "")
            given = units.get(component, {})
            lines.append(f"{component} {fmu.rsplit('/', 1)[-1]}: " + ", ".join(
                f"{name} = {value(x, given.get(name, ''), degrees)}"
                for name, x in p[component].items()))
    if meta.get("overrides"):
        lines.append(f"set: {overrides(meta)}")
    if meta.get("events"):
        lines.append("events: " + "; ".join(
            f"{e['time']:g} s {e['action']} {e['model']}.{e['variable']}"
            + ("" if e["value"] is None else f" {e['value']!r}") for e in meta["events"]))
    return lines


def changes(meta: dict[str, Any]) -> str:
    """How the run differs from its scenario, as --set and --stop-time options."""
    changed = [overrides(meta)] if meta.get("overrides") else []
    changed += ["--events"] if meta.get("events") else []
    stop = meta.get("scenario_stop_time")
    if stop is not None and meta.get("stop_time", stop) != stop:
        changed.append(f"--stop-time {meta['stop_time']:g}")
    return " ".join(changed)


def paper_row(meta: dict[str, Any]) -> tuple[str, tuple[float, float, float]] | None:
    """The paper's table and (psi_E, delta_E, J) for one of its own runs, unchanged."""
    system = meta.get("system", "")
    if system not in PAPER_TABLES or changes(meta) or not meta.get("scenario_file") or \
            Path(meta["scenario_file"]).resolve() != (SCENARIO_DIR / f"{system}.ssd").resolve():
        return None
    return f"Tomera (2010) Table {1 if system.startswith('calm') else 2}", PAPER_TABLES[system]


def headline(label: str, meta: dict[str, Any]) -> str:
    if not (changed := changes(meta)):
        return f"{label}: {meta.get('description', '')}"
    whose = "the paper's" if meta.get("system") in PAPER_TABLES else "the scenario's"
    return f"{label}: {meta.get('system', label)} changed by {changed} (not {whose} run)"


def title(label: str, meta: dict[str, Any]) -> str:
    return "\n".join([headline(label, meta), *conditions(meta)])
