"""Line-of-sight guidance (issue 40): psi_d = pi_k - atan(e / Delta) on eq (18)'s legs, the
FMU in eq (18)'s place in a scenario, and the RL observation's cross-track error, its array
form, pinned to it."""
from __future__ import annotations

import math

import numpy as np
import pytest

import cosim
from autopilot_fmu.guidance import WaypointGuidance
from autopilot_fmu.los import LOSGuidance
from cosim.core.recording import Recording
from cosim.ensemble.control import GuidanceArrays
from cosim.rl.spaces import OBSERVATION, observe

ROUTE = "0,0;30,0;60,25;90,25"


def test_los_steers_back_onto_the_line_and_switches_legs_as_eq_18():
    los, eq18 = LOSGuidance(ROUTE, 2.51, 5.0), WaypointGuidance(ROUTE, 2.51)
    assert los.psi_d(10.0, 0.0) == eq18.psi_d(10.0, 0.0) == 0.0          # on the line
    assert los.cross_track(10.0, 3.0) == 3.0                           # east: starboard
    assert los.psi_d(10.0, 3.0) == pytest.approx(-math.atan(3.0 / 5.0))  # turns to port
    assert los.psi_d(10.0, -1e9) == pytest.approx(math.pi / 2)          # far off: across
    rng = np.random.default_rng(1)
    for x, y in rng.uniform((-5, -10), (100, 35), size=(300, 2)):      # a wandering track
        assert los.wp_index(x, y) == eq18.wp_index(x, y)
        los.update(x, y), eq18.update(x, y)
    with pytest.raises(ValueError, match="parameter lookahead must be finite and > 0, got 0"):
        LOSGuidance(ROUTE, 2.51, 0.0)


def test_the_rl_observations_cross_track_is_los_guidances():
    rng = np.random.default_rng(2)
    points = rng.uniform((-5, -10), (100, 35), size=(50, 2))
    route = GuidanceArrays([WaypointGuidance(ROUTE) for _ in points])
    x, y = points.T
    _, wp_index = route.outputs(x, y)
    signals = {"x": x, "y": y, "wp_index": wp_index, **dict.fromkeys(
        ("psi", "psi_d", "u", "r", "delta"), np.zeros(len(x)))}
    column = observe(route, signals)[:, list(OBSERVATION).index("cross_track")]
    for (xi, yi), e in zip(points, column):          # each a fresh guidance, as each lane
        assert e == LOSGuidance(ROUTE).cross_track(xi, yi)


def test_waves_pd_los_follows_the_legs_closer_than_eq_18():
    runs = {name: cosim.simulate(name, backend="inprocess", stop_time=300)
            for name in ("waves_pd", "waves_pd_los")}
    assert runs["waves_pd_los"].meta["backends"]["guidance"] == "inprocess"
    cross = {name: np.sqrt(np.mean(np.square(_cross_track(run)))) for name, run in runs.items()}
    assert cross["waves_pd_los"] < 0.6 * cross["waves_pd"], cross


def _cross_track(run: Recording) -> np.ndarray:
    """e along a run's track, legs switched as its guidance switched them."""
    los = LOSGuidance(ROUTE)
    out = []
    for x, y in zip(run["ship.x"], run["ship.y"]):
        out.append(los.cross_track(x, y))
        los.update(x, y)
    return np.array(out)
