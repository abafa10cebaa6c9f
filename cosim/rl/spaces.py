"""What the ship environments share: the loop without its autopilot, the observation and
action spaces, the observation and the reward (docs/rl.md). One function each, on arrays of
M ships, so that one ship and a thousand give the same bits."""
from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from gymnasium import spaces

from autopilot_fmu.guidance import leg_offsets

from ..analysis.metrics import stage_cost
from ..core.system import SystemDescription
from ..ensemble.control import GuidanceArrays
from ..ensemble.exact import wrap

OBSERVATION = {           # name: (unit, what)
    "e": ("rad", "heading error psi - psi_d, wrapped to (-pi, pi]"),
    "r": ("rad/s", "yaw rate"),
    "delta": ("rad", "rudder angle"),
    "u": ("m/s", "surge speed"),
    "cross_track": ("m", "distance from the active leg's line, positive to starboard of it"),
    "to_go": ("m", "along the active leg to its end waypoint"),
    "bearing": ("rad", "the active leg's bearing, eq (18), in (-pi, pi]"),
}
SIGNALS = ("guidance.psi_d", "guidance.wp_index", "ship.x", "ship.y", "ship.psi", "ship.u",
           "ship.r", "ship.delta")     # what the observation and the reward are made of
PILOT = "autopilot"


def open_loop(system: SystemDescription) -> SystemDescription:
    """``system`` without its autopilot: the ship's delta_c is the agent's action."""
    if PILOT not in system.components or "ship" not in system.components:
        raise ValueError(f"{system.name} has no autopilot to take the place of (its "
                         f"components: {', '.join(system.components)}); the ship environments "
                         "take a course-keeping scenario, e.g. calm_pd or waves_pd")
    return dataclasses.replace(
        system, components={n: c for n, c in system.components.items() if n != PILOT},
        connections=[c for c in system.connections if PILOT not in (c.start_element,
                                                                     c.end_element)])


def seeded(overrides: dict[str, dict[str, Any]], wave_seed: int) -> dict[str, dict[str, Any]]:
    """``overrides`` with the ship's wave realisation ``wave_seed``, as a sweep's seed sets it."""
    return {**overrides, "ship": {**overrides.get("ship", {}), "wave_seed": wave_seed}}


def observation_space(delta_max: float, count: int | None = None) -> spaces.Box:
    """Angles within (-pi, pi] and the rudder within its stops; the rest unbounded."""
    high = np.array([np.pi, np.inf, delta_max, np.inf, np.inf, np.inf, np.pi])
    return spaces.Box(-high, high, dtype=np.float64) if count is None else \
        spaces.Box(np.tile(-high, (count, 1)), np.tile(high, (count, 1)), dtype=np.float64)


def action_space(delta_max: float, count: int | None = None) -> spaces.Box:
    """delta_c, rad, within the gear's stops (beyond them the gear holds at the stop)."""
    return spaces.Box(-delta_max, delta_max, (1,) if count is None else (count, 1), np.float64)


def rudder_commands(action: Any, count: int) -> np.ndarray:
    """The (count,) commands of an action (count, 1); ValueError for any that is not finite."""
    delta_c = np.asarray(action, dtype=float)
    if delta_c.size != count:
        raise ValueError(f"action: {count} rudder command{'s' * (count > 1)} delta_c (shape "
                         f"{(count, 1) if count > 1 else (1,)}), got shape {delta_c.shape}")
    delta_c = delta_c.reshape(count)
    bad = np.flatnonzero(~np.isfinite(delta_c))
    if len(bad):
        raise ValueError(f"action: delta_c = {delta_c[bad[0]]} is not finite"
                         + (f" (ship {bad[0]})" if count > 1 else ""))
    return delta_c


def observe(route: GuidanceArrays, s: dict[str, np.ndarray]) -> np.ndarray:
    """The (M, 7) observations of M ships from their ``SIGNALS`` (short names: psi, x, ...)."""
    i = route.members
    leg = np.minimum(s["wp_index"].astype(int), route.points - 1) - 1
    (x0, y0), (dx, dy) = route.start[i, leg].T, route.delta[i, leg].T
    length = route.length[i, leg]
    cross, along = leg_offsets(s["x"], s["y"], x0, y0, dx, dy, length)
    return np.stack((wrap(s["psi"] - s["psi_d"]), s["r"], s["delta"], s["u"], cross,
                     length - along, route.course[i, leg]), axis=1)


def reward(s: dict[str, np.ndarray], lam: float, first: np.ndarray | float) -> np.ndarray:
    """Minus this sample's share of eq (19), and ``first`` (the share of t_0) on an
    episode's first step: an episode's return is -J."""
    return -(stage_cost(s["psi_d"], s["psi"], s["delta"], lam) + first)


def finished(route: GuidanceArrays, s: dict[str, np.ndarray]) -> np.ndarray:
    """Past the last waypoint."""
    return s["wp_index"] >= route.points


def short(signal: str) -> str:
    return signal.split(".", 1)[1]


MAX_SEED = 2**31 - 1                    # ship.wave_seed's range is 0 .. this
