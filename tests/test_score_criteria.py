"""The scorecard's criteria (cosim.analysis.metrics, merit.run_metrics), each on a
synthetic recording whose answer is known by construction; and the same criteria from other
tools' result files (cosim.score FILE.csv)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import cosim
from cosim import score
from cosim.analysis.metrics import (RUDDER_DEADBAND, course_settling, cross_track_error,
                                    fraction_at_stops, mean_abs_rate, peak, rms,
                                    route_completion, rudder_reversals_per_minute)
from cosim.core.recording import Recording
from cosim.studies.merit import METRICS, run_metrics


def _leg_track(start, course: float, offset: float, length: float, n: int = 201):
    """Points along a line at ``course`` (rad, from north) through ``start``, ``offset`` m to
    starboard of it (north x, east y)."""
    s = np.linspace(0.0, length, n)
    x = start[0] + s * math.cos(course) - offset * math.sin(course)
    y = start[1] + s * math.sin(course) + offset * math.cos(course)
    return x, y


@pytest.mark.parametrize("offset", [2.5, -4.0])
def test_a_track_parallel_to_a_leg_is_off_it_by_its_offset_starboard_positive(offset):
    points = [(10.0, -5.0), (40.0, 25.0)]              # a leg to the north-east, 45 deg
    x, y = _leg_track(points[0], math.pi / 4, offset, 42.0)
    error = cross_track_error(x, y, np.ones_like(x), points)
    assert error == pytest.approx(np.full_like(x, offset))
    assert rms(error) == pytest.approx(abs(offset)) and peak(error) == pytest.approx(abs(offset))


def test_the_cross_track_error_is_from_the_leg_the_guidance_follows():
    points = [(0.0, 0.0), (30.0, 0.0), (30.0, 30.0)]   # north, then east
    # 3 m east of the first leg while steering to waypoint 1, then 1 m south of the second
    # (to starboard, heading east), and past the last waypoint (wp_index 3) still 1 m south
    x = np.array([10.0, 20.0, 29.0, 29.0, 29.0])
    y = np.array([3.0, 3.0, 10.0, 20.0, 40.0])
    wp_index = np.array([1, 1, 2, 2, 3])
    assert cross_track_error(x, y, wp_index, points) == pytest.approx([3, 3, 1, 1, 1])


def test_a_route_is_completed_only_if_the_track_comes_within_the_circle_of_its_last_point():
    points = [(0.0, 0.0), (50.0, 0.0), (100.0, 0.0)]
    x, y = _leg_track(points[0], 0.0, 1.0, 100.0)       # 1 m to starboard, all the way
    done = route_completion(x, y, points, R_accept=2.0)
    assert done.closest == pytest.approx((1.0, 1.0, 1.0))
    assert done.reached == (True, True, True) and done.count == 3 and done.last_reached
    short = route_completion(x[x <= 90.0], y[x <= 90.0], points, R_accept=2.0)
    assert short.closest[-1] == pytest.approx(math.hypot(10.0, 1.0))
    assert short.count == 2 and not short.last_reached
    off = route_completion(x, y + 5.0, points, R_accept=2.0)   # 6 m off: nothing reached
    assert off.count == 0 and off.closest == pytest.approx((6.0, 6.0, 6.0))


def test_a_rudder_dithering_about_amidships_does_not_reverse():
    """Head seas leave a rounding residue in the wave side force: the rudder flips sign at
    1e-15 rad every step; that, or a dither inside the deadband, is no reversal."""
    t = np.arange(0.0, 60.0 + 1e-9, 0.1)
    flips = 1e-15 * (-1.0) ** np.arange(t.size)
    assert rudder_reversals_per_minute(t, flips) == 0.0
    small = 0.9 * RUDDER_DEADBAND * np.sin(2 * math.pi * 0.5 * t)
    assert rudder_reversals_per_minute(t, small) == 0.0
    # past the deadband each way, twice: two reversals in the minute, whatever dithers between
    swing = np.where(t < 20, 2 * RUDDER_DEADBAND, np.where(t < 40, -2 * RUDDER_DEADBAND,
                                                            2 * RUDDER_DEADBAND)) + flips
    assert rudder_reversals_per_minute(t, swing) == pytest.approx(2.0)


def test_a_rudder_sine_reverses_twice_a_period_and_travels_four_amplitudes_a_period():
    amplitude, f = math.radians(10.0), 0.05            # 10 deg at 20 s period
    t = np.arange(0.0, 600.0 + 1e-9, 0.1)               # 30 whole periods
    delta = amplitude * np.sin(2 * math.pi * f * t + 0.3)
    assert rudder_reversals_per_minute(t, delta) == pytest.approx(2 * f * 60.0)
    assert mean_abs_rate(t, delta) == pytest.approx(4 * amplitude * f, rel=1e-3)
    # the same sine about 15 deg of helm never crosses over: no reversal, the same travel
    assert rudder_reversals_per_minute(t, delta + math.radians(15.0)) == 0.0
    assert mean_abs_rate(t, delta + math.radians(15.0)) == pytest.approx(mean_abs_rate(t, delta))


def test_the_time_on_the_stops_counts_the_samples_at_the_limit():
    stops = math.radians(35.0)
    delta = np.clip(np.linspace(-2 * stops, 2 * stops, 401), -stops, stops)
    # |delta| >= stops where |linspace| >= stops: the outer halves of the ramp
    assert fraction_at_stops(delta, stops) == pytest.approx(202 / 401)


def test_a_run_s_row_carries_every_criterion_with_the_known_answers():
    t = np.arange(0.0, 100.0 + 1e-9, 0.1)
    x, y = 0.3 * t, np.full_like(t, -2.0)              # 2 m to port of a northbound route
    psi_d = np.zeros_like(t)
    psi = np.full_like(t, -0.05)                        # 0.05 rad to port of the course
    delta = np.full_like(t, math.radians(35.0))         # hard over all along
    columns = ["guidance.psi_d", "guidance.wp_index", "ship.x", "ship.y", "ship.psi",
               "ship.delta"]
    data = np.column_stack([psi_d, np.where(x < 15.0, 1, 2), x, y, psi, delta])
    meta = {"step_size": 0.1, "parameters": {
        "guidance": {"waypoints": "0,0;15,0;40,0", "R_accept": 2.51},
        "ship": {"delta_max": math.radians(35.0)}}}
    row = run_metrics(Recording(columns, t, data, rows=len(t), meta=meta))
    assert set(row) == set(METRICS)
    assert row["rms_heading_error_deg"] == pytest.approx(math.degrees(0.05))
    assert row["cross_track_rms_m"] == pytest.approx(2.0)
    assert row["cross_track_max_m"] == pytest.approx(2.0)
    assert row["max_delta_deg"] == pytest.approx(35.0) and row["at_stops_pct"] == 100.0
    assert row["reversals_per_min"] == 0.0 and row["mean_rudder_rate_deg_s"] == 0.0
    # the track ends at x = 30 m: the start and (15, 0) reached, 2 m off; (40, 0) not
    assert (row["waypoints_reached"], row["waypoints"], row["last_waypoint_reached"]) == \
        (2.0, 3.0, 0.0)
    assert row["psi_E"] == pytest.approx(len(t) * 0.05 ** 2)
    assert row["waypoint_margin_m"] == pytest.approx(2.51 - math.hypot(10.0, 2.0))  # (40, 0)
    assert math.isnan(row["course_settling_s"])         # psi_d never changes


def test_the_heading_settles_when_it_stays_within_five_percent_of_the_change():
    t = np.arange(0.0, 200.0 + 1e-9, 0.1)
    wp_index = np.where(t < 50.0, 1, np.where(t < 120.0, 2, 3))   # two course changes
    psi_d = np.where(wp_index == 2, 0.6, 0.0)
    error = np.where(wp_index == 2, 0.6 * np.clip(1.0 - (t - 50.0) / 10.0, 0.0, 1.0),
                     np.where(wp_index == 3, -0.6 * np.exp(-(t - 120.0) / 10.0), 0.0))
    # within 5 % (0.03 rad): 9.5 s after the first change, 10 ln 20 = 29.96 s after the second
    assert course_settling(t, psi_d, psi_d - error, wp_index) == \
        pytest.approx((9.5 + 30.0) / 2, abs=0.051)


def test_other_tools_result_files_give_the_same_criteria(tmp_path, capsys):
    run = cosim.simulate("calm_pd", stop_time=150, backend="inprocess")
    ours = tmp_path / "ours.csv"
    run.write_csv(ours)
    header, *rows = [line.split(",") for line in ours.read_text().splitlines()]
    oms = tmp_path / "oms.csv"                          # OMSimulator's names, a time twice
    oms.write_text("\n".join([",".join('"time"' if c == "time" else f'"calm_pd.calm_pd.{c}"'
                                        for c in header),
                              *(",".join(row) for row in [rows[0], *rows])]))
    for component in ("guidance", "ship"):              # libcosim's: a file per component
        keep = [i for i, c in enumerate(header) if c.startswith(component + ".")]
        lines = [",".join(["Time", "StepCount", *(header[i].split(".", 1)[1] for i in keep)])]
        lines += [",".join([row[0], str(k), *(row[i] for i in keep)])
                  for k, row in enumerate(rows)]
        (tmp_path / f"{component}_20261203_212550_085466.csv").write_text("\n".join(lines))
    expected = run_metrics(run)
    for files in ([ours], [oms], sorted(tmp_path.glob("*_2026*.csv"))):
        assert score.main([str(f) for f in files]) == 0
        text = capsys.readouterr().out
        assert f"| J of eq (19) (rad^2) | {expected['J']:.1f} |" in text, files
        assert f"| waypoints reached | {expected['waypoints_reached']:.0f} of 4 |" in text
    assert score.main([str(tmp_path / "ship_20261203_212550_085466.csv")]) == 2
    assert "hold no guidance.psi_d, guidance.wp_index" in capsys.readouterr().err
    (tmp_path / "bad.csv").write_text("time,ship.psi\n0,abc\n")
    assert score.main([str(tmp_path / "bad.csv")]) == 2
    assert "result file" in capsys.readouterr().err
