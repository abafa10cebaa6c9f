"""Titles and headers of a run from the parameter values the FMUs held (``Recording.meta``),
never typed per scenario: a label cannot describe a run that was not made."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from autopilot_fmu.guidance import route as followed_route

from ..scenarios import SCENARIO_DIR
from .reports import PAPER_TABLES


def value(x: Any, unit: str = "", degrees: bool = True) -> str:
    """A parameter value, 4 significant digits; angles in degrees if ``degrees``."""
    if isinstance(x, float) and degrees and unit in ("rad", "rad/s"):
        x, unit = x * math.degrees(1.0), unit.replace("rad", "deg")
    text = f"{x:.4g}" if isinstance(x, float) else str(x)
    return f"{text} {'' if unit == '1' else unit}".strip()


def overrides(meta: dict[str, Any]) -> str:
    """The settings on top of the scenario, as --set options."""
    return " ".join(f"--set {c}.{n}={x}" for c, values in meta.get("overrides", {}).items()
                    for n, x in values.items())


def conditions(meta: dict[str, Any]) -> list[str]:
    """What a run was, line by line."""
    p, units = meta.get("parameters", {}), meta.get("parameter_units", {})
    lines = []
    if "stop_time" in meta:
        lines.append(f"{meta['stop_time'] - meta['start_time']:g} s in steps of "
                     f"{meta['step_size']:g} s, {meta['coupling']} coupling, "
                     f"{meta['backend']} backend")
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
    return lines


def changes(meta: dict[str, Any]) -> str:
    """How the run differs from its scenario, as --set and --stop-time options."""
    changed = [overrides(meta)] if meta.get("overrides") else []
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
