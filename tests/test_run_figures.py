"""The run figures as a marine engineer reads them (issue 27): the figures of merit of eq (19)
beside the paper's, truthful titles, named waypoints, visible ship outlines, the rudder's sign,
the actual rudder readable under a chattering command, nothing drawn over the data, and a
comparison framed on the tracks. Figures are checked with matplotlib's own renderer."""
from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.text import Text

from cosim import simulate
from cosim.analysis.animation import leg_text
from cosim.analysis.metrics import cost
from cosim.analysis.figures import RUDDER_LABEL, comparison, course_keeping_figure
from cosim.analysis.track import outline_scale, waypoint_name
from cosim.analysis.reports import PAPER_TABLES, paper_row, title
from cosim.studies.scorecard import COURSE_CHANGE_ROUTE, COURSE_CHANGE_TIME
from ship_fmu.data import Hull

CHANGED = {"ship.Hs": 0.0268, "ship.T0": 1.1}
"""The engineer's run: waves_pd in a sea that puts its rudder on the stops for minutes."""


def _run(scenario: str, **kwargs):
    return simulate(scenario, backend="inprocess", **kwargs)


@pytest.fixture(scope="module")
def calm_pd(fmu_paths):
    return _run("calm_pd")


@pytest.fixture(scope="module")
def calm_smc(fmu_paths):
    return _run("calm_smc")


@pytest.fixture(scope="module")
def waves_smc(fmu_paths):
    return _run("waves_smc")


@pytest.fixture(scope="module")
def changed(fmu_paths):
    return _run("waves_pd", set=CHANGED)


@pytest.fixture(scope="module")
def course_change(fmu_paths):
    return {name: _run(scenario, set={"guidance.waypoints": COURSE_CHANGE_ROUTE},
                       stop_time=COURSE_CHANGE_TIME)
            for name, scenario in (("PD", "calm_pd"), ("SMC", "calm_smc"))}


def _texts(fig) -> str:
    """Every piece of text in the figure: titles, notes, annotations, legends."""
    return " | ".join(t.get_text() for t in fig.findobj(Text) if t.get_text())


def _track(fig):
    return fig.axes[0]


def test_the_figure_carries_eq19_as_analysis_cost_computes_it_and_the_papers_table(calm_pd):
    text = _texts(course_keeping_figure(calm_pd))
    c = cost(calm_pd)
    for number in (c.psi_E, c.delta_E, c.J):
        assert f"{number:.2f}" in text
    assert f"{c.sum_delta2:.3f}" in text and f"{c.lam:.4f}" in text
    paper = PAPER_TABLES["calm_pd"]
    assert "Tomera (2010) Table 1" in text
    assert all(f"{number:.2f}" in text for number in paper)
    other = cost(calm_pd, 2.0)                        # --lambda 2 draws that lambda's J
    assert f"{other.J:.2f}" in _texts(course_keeping_figure(calm_pd, lam=2.0))
    assert f"{other.J:.2f}" not in text


def test_a_run_changed_by_set_is_titled_as_the_scenario_changed_not_as_the_papers(changed):
    heading = title("waves_pd", changed.meta).splitlines()[0]
    assert heading == ("waves_pd: waves_pd changed by --set ship.Hs=0.0268 --set ship.T0=1.1 "
                       "(not the paper's run)")
    assert "Table" not in title("waves_pd", changed.meta)
    assert paper_row(changed.meta) is None
    text = _texts(course_keeping_figure(changed))
    assert f"{cost(changed).J:.2f}" in text
    assert "Tomera" not in text and f"{PAPER_TABLES['waves_pd'][2]:.2f}" not in text


def test_a_shortened_run_is_not_the_papers_either(fmu_paths):
    short = _run("waves_pd", stop_time=60)
    assert title("waves_pd", short.meta).splitlines()[0] == \
        "waves_pd: waves_pd changed by --stop-time 60 (not the paper's run)"
    assert paper_row(short.meta) is None


def test_only_the_projects_own_paper_scenarios_get_the_papers_values(waves_smc):
    assert title("waves_smc", waves_smc.meta).startswith(
        "waves_smc: Tomera (2010) Table 2 / Fig 3")
    assert paper_row(waves_smc.meta) == ("Tomera (2010) Table 2", PAPER_TABLES["waves_smc"])
    yours = {**waves_smc.meta, "system": "waves_smc-mine"}         # your autopilot's run
    assert paper_row(yours) is None
    elsewhere = {**waves_smc.meta, "scenario_file": "/elsewhere/waves_smc.ssd"}
    assert paper_row(elsewhere) is None


def test_waypoints_are_named_from_wp1_at_their_points(fmu_paths):
    """Eq (18) counts the waypoint passed k and the next k + 1; the start is WP1."""
    route = "0,0;20,0;40,10;60,10;80,0"
    run = _run("calm_pd", set={"guidance.waypoints": route}, stop_time=120)
    points = [tuple(map(float, p.split(","))) for p in route.split(";")]
    labels = [t for t in _track(course_keeping_figure(run)).texts
              if t.get_text().startswith("WP")]
    assert [t.get_text() for t in labels] == ["WP1", "WP2", "WP3", "WP4", "WP5"]
    assert [t.xy for t in labels] == [(east, north) for north, east in points]
    # The animation names the leg as the figure names its points: at t = 0 the guidance
    # steers from the start to the second point.
    steering = int(run["guidance.wp_index"][0])
    assert points[steering] == (20.0, 0.0)
    assert leg_text(steering, np.array(points)) == "leg WP1 -> WP2 (20, 0) m"
    assert leg_text(len(points), np.array(points)) == \
        f"past {waypoint_name(4)}, the last: holding its course"


def _inside(box, xy: np.ndarray) -> np.ndarray:
    """Which display points lie inside ``box``, more than a pixel from its edge."""
    return ((box.x0 + 1 < xy[:, 0]) & (xy[:, 0] < box.x1 - 1) &
            (box.y0 + 1 < xy[:, 1]) & (xy[:, 1] < box.y1 - 1))


def _covered(fig) -> list[str]:
    """Which legends and texts (notes, titles, waypoint names) cover plotted line data:
    a point of a line (its segments cut in 20) shown in its axes and inside the text's or
    legend's box, in display pixels, as matplotlib's renderer lays them out."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = [(f"legend {i}", legend.get_window_extent(renderer))
             for i, legend in enumerate(fig.legends)]
    for ax in fig.axes:
        boxes += [(repr(child.get_text()) if isinstance(child, Text) else "legend",
                   child.get_window_extent(renderer)) for child in ax.get_children()
                  if (isinstance(child, Text) and child.get_text()) or
                  child is ax.get_legend()]
    found = []
    for ax in fig.axes:
        frame = ax.get_window_extent(renderer)
        for line in ax.lines:
            xy = line.get_transform().transform(line.get_path().interpolated(20).vertices)
            xy = xy[np.isfinite(xy).all(axis=1)]
            xy = xy[_inside(frame, xy)]
            found += [f"{name} covers {line.get_label()}" for name, box in boxes
                      if _inside(box, xy).any()]
    return found


@pytest.mark.parametrize("which", ["calm_pd", "calm_smc", "waves_smc", "changed"])
def test_no_legend_or_note_covers_the_data(which, request):
    run = request.getfixturevalue(which)
    assert _covered(course_keeping_figure(run)) == []


def test_no_legend_covers_the_comparison(course_change):
    assert _covered(comparison(course_change, "course change")) == []


def test_the_rudder_axes_say_a_positive_rudder_turns_to_port_as_the_model_does(
        calm_pd, course_change):
    assert "+ turns to port" in RUDDER_LABEL
    assert course_keeping_figure(calm_pd).axes[-1].get_ylabel() == RUDDER_LABEL
    assert comparison(course_change, "course change").axes[-1].get_ylabel() == RUDDER_LABEL
    turn = _run("turning_circle")           # north x, east y, psi clockwise from north:
    assert turn["ship.delta"][-1] > 0       # to port is a falling heading, r < 0
    assert turn["ship.r"][-1] < 0 and turn["ship.psi"][-1] < turn["ship.psi"][0]


def test_the_smc_actual_rudder_is_drawn_over_its_chattering_command(calm_smc):
    rudder = course_keeping_figure(calm_smc).axes[-1]
    lines = {line.get_label(): line for line in rudder.lines}
    command, actual = lines["commanded delta_c"], lines["actual delta"]
    assert actual.get_zorder() > command.get_zorder()
    assert command.get_alpha() < 1 and command.get_linewidth() < actual.get_linewidth()
    stops = math.degrees(calm_smc.meta["parameters"]["ship"]["delta_max"])
    assert np.abs(command.get_ydata()).max() > 10 * stops      # it chatters far past them
    assert rudder.get_ylim() == pytest.approx((-1.15 * stops, 1.15 * stops))
    assert "clipped" in rudder.get_title(loc="left")            # said above, not over it


def test_the_comparison_frames_the_tracks_and_says_where_the_route_goes(course_change):
    fig = comparison(course_change, "course change")
    fig.canvas.draw()
    track = _track(fig)
    (west, east), (south, north) = track.get_xlim(), track.get_ylim()
    tracks = np.concatenate([np.column_stack([r["ship.y"], r["ship.x"]])
                             for r in course_change.values()])
    assert west < tracks[:, 0].min() and tracks[:, 0].max() < east
    assert south < tracks[:, 1].min() and tracks[:, 1].max() < north
    span = np.ptp(tracks, axis=0).max()
    assert max(east - west, north - south) < 1.6 * span        # not the 1000 m leg
    far_north, far_east = map(float, COURSE_CHANGE_ROUTE.split(";")[1].split(","))
    assert north < far_north and east < far_east
    legend = _texts(fig)
    assert f"continuing out of view to WP2 ({far_north:g}, {far_east:g}) m" in legend


def test_the_ship_outline_is_enlarged_to_be_seen_by_a_stated_factor():
    assert Hull.L == pytest.approx(1.255)
    # 30 s apart at 0.3 m/s: 9 m; 0.8 of it is 7.2 m, so 5 lengths (6.3 m), not 6 (7.5 m)
    assert outline_scale(9.0, 110.0) == 5
    assert outline_scale(0.5, 5.0) == 1           # a turning circle: the ship to scale
    assert outline_scale(300.0, 12_000.0) == 100   # 0.8 x 300 = 240 m: 191 lengths
    for spacing, extent in ((9.0, 110.0), (40.0, 2000.0), (3.0, 30.0), (80.0, 500.0)):
        scale = outline_scale(spacing, extent)
        room = min(0.8 * spacing, extent / 12)
        step = 10 ** math.floor(math.log10(scale))
        assert scale * Hull.L <= room < (scale + step) * Hull.L
