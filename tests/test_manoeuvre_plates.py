"""The IMO manoeuvre figures, criteria and plates: figures computed from synthetic trajectories
whose answers follow from their construction, the MSC.137(76) limits at their boundaries, and
plates that draw what the report says."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cosim import simulate
from cosim.analysis.manoeuvres import (ADVANCE_LIMIT, TACTICAL_DIAMETER_LIMIT, Criterion,
                                       TurningCircle, ZigZagResult, steady_circle,
                                       length_over_speed, overshoot_limits,
                                       turning_circle_criteria, turning_circle_figures,
                                       turning_circle_of, zigzag_criteria, zigzag_figures,
                                       zigzag_of)
from cosim.analysis.plates import turning_circle_plate, zigzag_plate
from cosim.analysis.reports import criterion_text, turning_circle_report, zigzag_report
from cosim.outputs import figure
from cosim.analysis.seastate import SCALE
from cosim.core.recording import Recording
from ship_fmu.data import Hull
from ship_fmu.manoeuvres import RudderProgram

DEG = math.radians(1.0)
STEP = 0.01                          # s, of the synthetic trajectories


# -- a synthetic zig-zag: psi = -A1 sin(w t) for the first half cycle, -A2 sin(w t) after ---
W, A1, A2, U = 2 * math.pi / 40.0, 32.0 * DEG, 27.0 * DEG, 0.25


def _zigzag_track(switch: float, delta: float, t_end: float = 130.0) -> dict[str, np.ndarray]:
    """Heading, straight-line track at speed U and the rudder program's own reversals."""
    t = np.arange(0.0, t_end, STEP)
    psi = -np.where(t < math.pi / W, A1, A2) * np.sin(W * t)
    program, reversals, command = RudderProgram(delta, switch), [], []
    for heading in psi:
        command.append(program.command(heading))
        program.update(heading)
        reversals.append(program.reversals)
    return {"t": t, "psi": psi, "x": U * t, "y": 0.0 * t, "reversals": np.array(reversals),
            "delta": np.array(command)}


def test_zigzag_figures_of_a_constructed_heading_history():
    s = 10.0 * DEG
    track = _zigzag_track(s, 10.0 * DEG)
    zz = zigzag_figures(track["psi"], track["reversals"], s, track["t"], track["x"],
                        track["y"])
    second, third = math.asin(s / A1) / W, (math.pi + math.asin(s / A2)) / W
    fourth = (2 * math.pi + math.asin(s / A2)) / W
    assert zz.executes[0] == 0.0
    assert zz.executes[1:4] == pytest.approx([second, third, fourth], abs=STEP)
    assert zz.initial_turning_time == pytest.approx(second, abs=STEP)
    assert zz.overshoots[0].angle == pytest.approx(A1 - s, abs=1e-6)
    assert zz.overshoots[1].angle == pytest.approx(A2 - s, abs=1e-6)
    assert zz.overshoots[0].time == pytest.approx(math.pi / 2 / W, abs=STEP)
    assert zz.overshoots[0].heading < 0 < zz.overshoots[1].heading
    assert zz.time_to_check_yaw == pytest.approx(math.pi / 2 / W - second, abs=STEP)
    assert zz.period == pytest.approx(fourth - second, abs=STEP)
    assert zz.initial_turning_distance == pytest.approx(U * second, rel=1e-4)  # interpolated
    assert zz.checked and zz.reversals == len(zz.executes) - 1


def test_an_overshoot_counts_once_the_heading_turns_back_before_the_next_execute():
    s = 10.0 * DEG
    track = _zigzag_track(s, 10.0 * DEG, t_end=0.8 * math.pi / W)    # back, not yet at +s
    zz = zigzag_figures(track["psi"], track["reversals"], s, track["t"], track["x"],
                        track["y"])
    assert zz.reversals == 1 and zz.running is None and not zz.checked
    assert zz.overshoots[0].angle == pytest.approx(A1 - s, abs=1e-6)
    assert zz.overshoot_bound(2) == (pytest.approx(math.nan, nan_ok=True), False)
    assert zigzag_criteria(zz, 20.0 * DEG, U) == ()        # 20 deg of rudder, 10 of heading


def test_a_run_ending_in_a_later_turn_is_a_checked_zigzag():
    s = 10.0 * DEG
    track = _zigzag_track(s, 10.0 * DEG, t_end=125.0)    # heading still going away at 125 s
    zz = zigzag_figures(track["psi"], track["reversals"], s, track["t"], track["x"],
                        track["y"])
    assert zz.reversals == 7 and zz.running is None and zz.checked   # reversed at 122.4 s


def test_a_turn_never_checked_has_no_overshoot_and_fails_its_criteria():
    s = 10.0 * DEG
    t = np.arange(0.0, 60.0, STEP)
    psi = -0.02 * t                                  # keeps turning to port
    reversals = np.where(np.abs(psi) >= s, 1, 0)
    zz = zigzag_figures(psi, reversals, s, t, 0.3 * t, 0.0 * t)
    assert not zz.checked and zz.overshoots == ()
    assert math.isnan(zz.time_to_check_yaw)
    assert math.isnan(zz.period)
    assert zz.initial_turning_time == pytest.approx(s / 0.02, abs=STEP)
    assert zz.running.angle == pytest.approx(0.02 * t[-1] - s, rel=1e-3)   # so far
    turning, first, second = zigzag_criteria(zz, 10.0 * DEG, 0.3)
    assert (turning.verdict, first.verdict, second.verdict) == ("PASS", "FAIL", "OPEN")
    assert first.at_least and criterion_text(first).startswith("FAIL  first overshoot at least")


# -- a synthetic turning circle: a circle of radius R to port, the drift growing to BETA ----
R, BETA, GROW = 2.0, 60.0 * DEG, 30.0 * DEG
SAMPLE = 2 * math.pi / 8000             # rad of course between two samples


def _circle(psi0: float = 0.0, x0: float = 0.0, y0: float = 0.0,
            laps: float = 2.5) -> dict[str, np.ndarray]:
    """The course turns by theta along the circle; the bow leads it by the drift angle,
    which grows linearly from 0 to BETA over the first GROW of course change."""
    theta = np.arange(0.0, laps * 2 * math.pi, SAMPLE)
    beta = BETA * np.minimum(1.0, theta / GROW)
    along, across = R * np.sin(theta), -R * (1.0 - np.cos(theta))     # to port
    c, s = math.cos(psi0), math.sin(psi0)
    speed = 0.2
    return {"x": x0 + along * c - across * s, "y": y0 + along * s + across * c,
            "psi": psi0 - theta - beta, "u": speed * np.cos(beta), "v": speed * np.sin(beta),
            "r": np.full_like(theta, -speed / R)}


@pytest.mark.parametrize("start", [(0.0, 0.0, 0.0), (1.0, 5.0, -3.0)])
def test_turning_circle_figures_of_a_constructed_circle(start):
    """Heading change 90 deg at 30 deg of course (60 of drift), 180 deg at 120 deg of course:
    advance R sin 30, transfer R (1 - cos 30), tactical diameter R (1 - cos 120) = 1.5 R,
    below the steady 2 R, whatever the approach course and start point."""
    track = _circle(*start)
    tc = turning_circle_figures(*(track[n] for n in ("x", "y", "psi", "u", "v", "r")))
    near = R * SAMPLE                   # the interpolation's error across the drift's kink
    assert tc.advance == pytest.approx(R * math.sin(GROW), abs=near)
    assert tc.transfer == pytest.approx(R * (1 - math.cos(GROW)), abs=near)
    assert tc.tactical_diameter == pytest.approx(1.5 * R, abs=near)
    assert tc.steady_diameter == pytest.approx(2 * R, rel=1e-9)
    assert tc.diameter_from_rates == pytest.approx(2 * R)
    assert tc.drift_angle == pytest.approx(BETA)
    assert tc.course_change_at_tactical == pytest.approx(math.pi - BETA, abs=SAMPLE)
    assert tc.approach_speed == pytest.approx(0.2) and tc.steady_speed == pytest.approx(0.2)


def test_no_steady_diameter_without_a_lap_past_the_first_half_turn():
    track = _circle(laps=1.2)                 # 432 deg of course, 492 of heading
    tc = turning_circle_figures(*(track[n] for n in ("x", "y", "psi", "u", "v", "r")))
    assert math.isnan(tc.steady_diameter) and tc.tactical_diameter > 0


def test_the_circle_fit_finds_centre_and_diameter():
    a = np.linspace(0, 10.0, 100)          # over 540 deg: the last lap is fitted
    assert steady_circle(1.0 + 3.0 * np.cos(a), -2.0 + 3.0 * np.sin(a), a) == \
        pytest.approx((1.0, -2.0, 6.0))


def test_the_simulated_steady_turn_is_consistent_with_its_recorded_velocities():
    """The fitted circle of the track equals 2U/|r| from u, v, r; the course at 180 deg
    heading change, from the track's tangent, is what the drift angle says."""
    run = simulate("turning_circle", backend="inprocess")         # 35 deg of rudder, 300 s
    track = {n: run[f"ship.{n}"] for n in ("x", "y", "psi", "u", "v", "r")}
    tc = turning_circle_figures(*(track[n] for n in ("x", "y", "psi", "u", "v", "r")))
    assert tc.steady_diameter == pytest.approx(tc.diameter_from_rates, rel=1e-6)
    k = int(np.argmax(np.abs(track["psi"]) >= math.pi))
    course = math.atan2(track["y"][k + 1] - track["y"][k - 1],
                        track["x"][k + 1] - track["x"][k - 1])
    assert abs(course) == pytest.approx(tc.course_change_at_tactical, abs=0.5 * DEG)
    assert tc.tactical_diameter < tc.steady_diameter          # the drift's doing


# -- the criteria at their boundaries ------------------------------------------------------
@pytest.mark.parametrize("lv, first, second", [
    (0.0, 10.0, 25.0), (9.999, 10.0, 25.0), (10.0, 10.0, 25.0), (20.0, 15.0, 32.5),
    (29.999, 20.0, 40.0), (30.0, 20.0, 40.0), (100.0, 20.0, 40.0)])
def test_10_10_overshoot_limits_follow_the_standard_and_are_continuous(lv, first, second):
    limits = overshoot_limits(lv)
    assert limits == pytest.approx((first * DEG, second * DEG), abs=0.001 * DEG)


def test_l_over_v_is_taken_at_full_scale_by_froude_scaling():
    full_length, full_speed = SCALE * Hull.L, 0.3 * math.sqrt(SCALE)   # same Froude number
    assert length_over_speed(Hull.L, 0.3) == pytest.approx(full_length / full_speed)
    assert length_over_speed(Hull.L, 0.3, scale=1.0) == pytest.approx(Hull.L / 0.3)


def test_a_criterion_passes_at_its_limit_fails_beyond_it_and_is_open_unmeasured():
    assert Criterion("advance", 4.5, 4.5, "L", "5.3.1").verdict == "PASS"
    assert Criterion("advance", math.nextafter(4.5, 5.0), 4.5, "L", "5.3.1").verdict == "FAIL"
    assert Criterion("first overshoot", math.nan, 0.3, "rad", "5.3.3.1").verdict == "OPEN"
    bound = Criterion("first overshoot", 0.2, 0.3, "rad", "5.3.3.1", at_least=True)
    assert bound.verdict == "OPEN"          # may still exceed 0.3
    assert Criterion("first overshoot", 0.4, 0.3, "rad", "5.3.3.1", at_least=True).verdict \
        == "FAIL"                                                   # exceeds it already


def test_a_turning_circle_cut_short_measures_what_it_reached():
    track = _circle(laps=0.3)                # 108 deg of course, 168 of heading
    tc = turning_circle_figures(*(track[n] for n in ("x", "y", "psi", "u", "v", "r")))
    assert tc.advance == pytest.approx(R * math.sin(GROW), abs=R * SAMPLE)
    assert math.isnan(tc.tactical_diameter)
    assert tc.heading_change == pytest.approx(math.radians(168), abs=SAMPLE)
    advance, tactical = turning_circle_criteria(tc, 35 * DEG, 35 * DEG)
    assert (advance.verdict, tactical.verdict) == ("PASS", "OPEN")
    assert "never changed by 180 deg" in criterion_text(tactical)


def _tc(advance_L: float, tactical_L: float) -> TurningCircle:
    return TurningCircle(advance_L * Hull.L, 0.1, tactical_L * Hull.L, -0.05, 0.15)


def test_turning_criteria_judge_the_35_deg_circle_in_ship_lengths():
    advance, tactical = turning_circle_criteria(_tc(ADVANCE_LIMIT, TACTICAL_DIAMETER_LIMIT),
                                                35 * DEG, 35 * DEG)
    assert (advance.verdict, tactical.verdict, advance.unit) == ("PASS", "PASS", "L")
    advance, tactical = turning_circle_criteria(_tc(4.6, 5.1), 35 * DEG, 35 * DEG)
    assert (advance.verdict, tactical.verdict) == ("FAIL", "FAIL")
    assert turning_circle_criteria(_tc(3, 3), 30 * DEG, 30 * DEG)   # the gear's largest
    assert turning_circle_criteria(_tc(3, 3), 20 * DEG, 35 * DEG) == ()


def test_zigzag_criteria_by_test():
    zz = ZigZagResult(3, 10 * DEG, initial_turning_distance=2.5 * Hull.L)
    turning, first, second = zigzag_criteria(zz, 10 * DEG, 0.3)
    assert turning.verdict == "PASS" and turning.limit == 2.5
    assert (first.limit, second.limit) == overshoot_limits(length_over_speed(Hull.L, 0.3))
    assert "35.0 s at full scale" in first.basis
    only, = zigzag_criteria(ZigZagResult(3, 20 * DEG), 20 * DEG, 0.3)
    assert only.limit == pytest.approx(25 * DEG) and only.clause == "5.3.3.3"
    assert zigzag_criteria(ZigZagResult(3, 15 * DEG), 15 * DEG, 0.3) == ()


# -- plates and reports from recordings ----------------------------------------------------
def _recording(track: dict[str, np.ndarray], program: dict, t: np.ndarray) -> Recording:
    columns = {"ship.x": track["x"], "ship.y": track["y"], "ship.psi": track["psi"],
               "ship.u": track["u"], "ship.v": track["v"], "ship.r": track["r"],
               "ship.delta": track["delta"], "ship.delta_c": track["delta"],
               "program.reversals": track["reversals"]}
    meta = {"parameters": {"program": program, "ship": {"delta_max": 35 * DEG, "Hs": 0.0}},
            "step_size": float(t[1] - t[0])}
    return Recording(list(columns), t, np.column_stack(list(columns.values())), len(t),
                     meta=meta)


@pytest.fixture(scope="module")
def zigzag_run() -> Recording:
    track = _zigzag_track(10 * DEG, 10 * DEG)
    r = np.gradient(track["psi"], STEP)
    track.update(u=np.full_like(r, U), v=0.0 * r, r=r)
    return _recording(track, {"delta": 10 * DEG, "psi_switch": 10 * DEG}, track["t"])


@pytest.fixture(scope="module")
def circle_run() -> Recording:
    track = _circle()
    n = len(track["x"])
    track.update(delta=np.full(n, 35 * DEG), reversals=np.zeros(n))
    return _recording(track, {"delta": 35 * DEG, "psi_switch": 0.0}, np.arange(n) * 0.05)


def _texts(fig) -> str:
    return " ".join(" ".join(t.get_text().split()) for ax in fig.axes for t in ax.texts)


def test_the_zigzag_plate_overlays_heading_and_rudder_and_prints_the_criteria(zigzag_run):
    fig = zigzag_plate(zigzag_run)
    heading = fig.axes[0]
    lines = {line.get_label(): line for line in heading.lines}
    np.testing.assert_array_equal(lines["rudder"].get_ydata(),
                                  -np.degrees(zigzag_run["ship.delta"]))  # starboard +
    np.testing.assert_array_equal(lines["heading psi"].get_ydata(),
                                  np.degrees(zigzag_run["ship.psi"]))
    a = zigzag_of(zigzag_run)
    assert len(lines["execute (rudder ordered)"].get_xdata()) == len(a.figures.executes)
    text = _texts(fig)
    assert "not checked" not in text and "still" not in text
    assert heading.get_xlim()[1] < zigzag_run.t[-1]           # zoomed on the first executes
    assert f"1st overshoot {math.degrees(A1) - 10:.1f} deg" in text
    assert f"2nd overshoot {math.degrees(A2) - 10:.1f} deg" in text
    assert f"period {a.figures.period:.1f} s" in text
    for line in zigzag_report(zigzag_run):
        assert " ".join(line.split()) in text                  # the report, on the plate
    verdicts = {t.get_text().split()[0]: t.get_color() for t in fig.axes[-1].texts}
    assert verdicts["PASS"] == "tab:green" and verdicts["FAIL"] == "tab:red"
    # L/V = sqrt(70) 1.255 m / 0.25 m/s = 42 s >= 30 s: limits 20 and 40 deg; the initial
    # turn took 2.0 s at 0.25 m/s, 0.4 L
    assert [c.verdict == "PASS" for c in a.criteria] == [
        True, A1 - 10 * DEG <= 20 * DEG, A2 - 10 * DEG <= 40 * DEG] == [True, False, True]


def test_the_turning_circle_plate_dimensions_what_the_report_says(circle_run):
    fig = turning_circle_plate(circle_run)
    track = fig.axes[0]
    a = turning_circle_of(circle_run)
    drawn = {line.get_gid(): line for line in track.lines if line.get_gid()}
    for name, length in (("advance", a.figures.advance), ("transfer", a.figures.transfer),
                         ("tactical", a.figures.tactical_diameter)):
        east, north = drawn[name].get_xdata(), drawn[name].get_ydata()
        assert math.hypot(east[1] - east[0], north[1] - north[0]) == pytest.approx(length)
    heading = fig.axes[1].lines[0].get_ydata()
    assert np.nanmin(heading) >= 0.0 and np.nanmax(heading) < 360.0     # wrapped
    text = _texts(fig)
    for line in turning_circle_report(circle_run):
        assert " ".join(line.split()) in text
    assert "course has turned only 120 deg" in text


def test_cosim_run_draws_the_plates():
    assert figure("zigzag") is zigzag_plate
    assert figure("turning_circle") is turning_circle_plate
