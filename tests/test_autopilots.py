"""Controllers and guidance as plain Python modules, and in closed loop with the ship."""
from __future__ import annotations

import math

import numpy as np
import pytest

from autopilot_fmu.design import PAPER_EQ45, NomotoModel, design_model, linearised_ship
from autopilot_fmu.guidance import WaypointGuidance, parse_waypoints
from autopilot_fmu.pd import PDAutopilot
from autopilot_fmu.smc import SlidingModeAutopilot, SlidingModeDesign
from cosim.analysis.metrics import (heading_error, overshoot, settling_time,
                                   rudder_reversals_per_minute)
from fmukit.numerics import wrap
from ship_fmu.vessel import Vessel

DT = 0.1
STEP = math.radians(40.0)


# -- design ----------------------------------------------------------------------
def test_eq_46_follows_from_eq_45():
    nomoto = NomotoModel.from_sway_yaw(PAPER_EQ45)
    assert nomoto.a22 == pytest.approx(0.1057, abs=5e-5)
    assert nomoto.b2 == pytest.approx(-0.0040, abs=5e-5)
    assert nomoto.T < 0.0          # the Munk moment makes the ship straight-line unstable


def test_sliding_mode_design_from_eq_45():
    design = SlidingModeDesign.from_model(PAPER_EQ45)
    assert design.K == pytest.approx((-0.98656, -1999.96), rel=1e-4)
    assert design.h == pytest.approx((0.99191, 0.12696), abs=1e-5)
    A = np.array([[0.0, 1.0], [0.0, design.nomoto.a22]])       # eq (33), state [psi, r]
    A_c = A - np.outer([0.0, design.nomoto.b2], design.K)
    assert sorted(np.linalg.eigvals(A_c).real) == pytest.approx([-7.8128, -0.0005])
    assert design.h @ A_c == pytest.approx(-0.0005 * np.array(design.h), abs=1e-12)


def test_linearised_ship_reproduces_eq_45_where_eq_45_is_consistent():
    model = linearised_ship(0.3)
    np.testing.assert_allclose(model.M, PAPER_EQ45.M, rtol=1e-12)
    np.testing.assert_allclose(model.N.ravel()[:3], PAPER_EQ45.N.ravel()[:3], atol=5e-5)
    assert model.N[1, 1] == pytest.approx(1.9 + 23.8 * 0.046 * 0.3, rel=1e-10)
    assert model.b[0] == pytest.approx(0.5366, abs=1e-4)
    assert model.b[1] / model.b[0] == pytest.approx(-0.549, rel=1e-10)


def test_design_model_names_are_checked():
    assert design_model("paper", 0.3) is PAPER_EQ45
    with pytest.raises(ValueError, match="design_model"):
        design_model("eq45", 0.3)
    with pytest.raises(ValueError, match="u0"):
        design_model("ship", 0.0)


# -- control laws ----------------------------------------------------------------
def test_pd_sign_and_wrapping():
    pd = PDAutopilot()
    assert pd.command(0.0, 0.0, 0.5) < 0.0                # turn to starboard: negative rudder
    assert pd.command(0.0, 0.01, 0.0) > 0.0               # damp a starboard yaw rate
    near_north = pd.command(math.radians(179.0), 0.0, math.radians(-179.0))
    assert near_north == pytest.approx(-2.0 * math.radians(2.0))


def test_reference_model_takes_the_short_way_across_north():
    smc = SlidingModeAutopilot(SlidingModeDesign.from_model(PAPER_EQ45),
                               psi_z=math.radians(170.0))
    psi_d = math.radians(-170.0)
    headings = []
    for k in range(1500):
        smc.step(k * DT, DT, psi_d)
        headings.append(smc.psi_z)
    assert wrap(smc.psi_z - psi_d) == pytest.approx(0.0, abs=1e-5)
    assert max(headings) < math.radians(190.5)        # overshoot of zeta = 0.85, no spin
    assert min(headings) >= math.radians(170.0) - 1e-12


def test_switching_term_pushes_toward_the_reference():
    smc = SlidingModeAutopilot(SlidingModeDesign.from_model(PAPER_EQ45), psi_z=0.2)
    assert smc.sigma(0.0, 0.0) > 0.0 and smc.command(0.0, 0.0, 0.2) < 0.0


@pytest.mark.parametrize("name", ["omega_n", "zeta", "phi_h"])
@pytest.mark.parametrize("value", [0.0, -1.0, math.nan])
def test_smc_refuses_bad_parameters_by_name(name, value):
    with pytest.raises(ValueError, match=name):
        SlidingModeAutopilot(SlidingModeDesign.from_model(PAPER_EQ45), **{name: value})


# -- guidance ----------------------------------------------------------------------
def test_guidance_eq_18_and_switching_in_the_circle():
    g = WaypointGuidance("0,0;30,0;60,25;90,25", R_accept=2.5)
    assert g.psi_d(10.0, 0.0) == 0.0 and g.wp_index(10.0, 0.0) == 1
    g.update(28.0, 0.5)                                   # inside the circle of (30, 0)
    assert g.leg == 1 and g.psi_d(28.0, 0.5) == pytest.approx(math.atan2(25.0, 30.0))


def test_guidance_switches_once_past_the_waypoint_outside_the_circle():
    g = WaypointGuidance("0,0;30,0;60,25", R_accept=2.5)
    g.update(30.5, 6.0)                                   # 6 m off track, but past x = 30
    assert g.leg == 1


def test_guidance_holds_the_last_course_after_the_last_waypoint():
    g = WaypointGuidance("0,0;30,0;60,25;90,25", R_accept=2.5)
    for x, y in [(30, 0), (60, 25), (95, 30), (150, -40)]:
        g.update(x, y)
    assert g.finished and g.wp_index(150, -40) == 4
    assert g.psi_d(150.0, -40.0) == 0.0


@pytest.mark.parametrize("text, fragment", [
    ("5,5", "at least two"), ("", "at least two"), ("0,0;a,1", "point 1"),
    ("0,0;1", "point 1"), ("0,0;1,2,3", "point 1"), ("0,0;0,0;1,1", "consecutive"),
    ("0,0;nan,1", "not finite"),
])
def test_bad_waypoints_are_refused_by_name(text, fragment):
    with pytest.raises(ValueError, match="waypoints") as refused:
        parse_waypoints(text)
    assert fragment in str(refused.value)


# -- closed loop, in-process -------------------------------------------------------
def heading_step(controller, seconds: float = 600.0):
    """Ship and controller modules, no FMI: a 40 deg course change from straight running."""
    vessel = Vessel()
    t, psi, delta = [], [], []
    for k in range(round(seconds / DT)):
        delta_c = controller.command(vessel.psi, vessel.r, STEP)
        if hasattr(controller, "step"):
            controller.step(k * DT, DT, STEP)
        vessel.step(k * DT, DT, delta_c)
        t.append(vessel.t), psi.append(vessel.psi), delta.append(vessel.delta)
    return np.array(t), np.array(psi), np.array(delta)


@pytest.mark.parametrize("name", ["pd", "smc"])
def test_40_deg_course_change_settles(name):
    controller = (PDAutopilot() if name == "pd"
                  else SlidingModeAutopilot(SlidingModeDesign.from_model(PAPER_EQ45)))
    t, psi, delta = heading_step(controller)
    band = 0.02 * STEP
    settle = settling_time(t, psi - STEP, band)
    over = overshoot(psi, 0.0, STEP)
    chatter = rudder_reversals_per_minute(t, delta)
    print(f"\n{name}: 40 deg course change settles (2 %) in {settle:.1f} s, overshoot "
          f"{math.degrees(over):.2f} deg, rudder reversals {chatter:.1f} per minute")
    assert settle < 500.0
    assert abs(psi[-1] - STEP) < band and np.all(np.abs(psi) < 2 * STEP)
    if name == "pd":
        assert settle < 100.0 and chatter < 5.0
    else:
        assert chatter > 20.0           # k2 ~ -2000 against a rate-limited gear: chattering


def test_the_pid_removes_the_pds_steady_heading_offset_in_oblique_waves():
    """One long leg at the route's second course (39.8 deg), waves from 180 deg: the mean
    wave yaw moment needs a steady rudder, which the PD buys with a heading offset."""
    from cosim import simulate

    offsets = {}
    for scenario in ("waves_pd", "waves_pid"):
        run = simulate(scenario, set={"guidance.waypoints": "0,0;300,251"}, backend="inprocess")
        late = run.t > 200.0
        offsets[scenario] = heading_error(run["guidance.psi_d"], run["ship.psi"])[late].mean()
        print(f"{scenario}: mean heading error after 200 s {math.degrees(offsets[scenario]):.3f}"
              f" deg, mean rudder {math.degrees(run['ship.delta'][late].mean()):.2f} deg")
    assert math.degrees(offsets["waves_pd"]) > 2.0
    assert abs(math.degrees(offsets["waves_pid"])) < 0.05
