"""What a run shows and writes: track panels, annotated manoeuvres, animations, truthful
labels, metadata. Figures are checked for what can be checked without looking."""
from __future__ import annotations

import hashlib
import json
import math
import sys

import numpy as np
import pytest
from fmpy import read_model_description
from matplotlib.patches import Circle, Polygon
from tqdm import tqdm

from cosim import run as cli
from cosim import simulate
from cosim.analysis.animation import animate, frame_times
from cosim.analysis.figures import RUDDER_LABEL, course_keeping_figure, save
from cosim.analysis.track import outlines
from cosim.analysis.manoeuvres import zigzag_of
from cosim.provenance import write_metadata
from cosim.core.recording import Recording
from ship_fmu.data import Hull


@pytest.fixture(scope="module")
def waves(fmu_paths):
    return simulate("waves_pd", set={"ship.Hs": 0.008})


def _texts(ax) -> str:
    return " | ".join(t.get_text() for t in ax.texts)


def test_the_track_panel_is_north_up_at_equal_scale_with_route_circles_and_switches(waves):
    fig = course_keeping_figure(waves)
    track = fig.axes[0]
    assert track.get_aspect() == 1.0
    assert (track.get_xlabel(), track.get_ylabel()) == ("east y (m)", "north x (m)")
    route = next(line for line in track.lines if line.get_label() == "route")
    np.testing.assert_array_equal(route.get_xdata(), [0, 0, 25, 25])      # east
    np.testing.assert_array_equal(route.get_ydata(), [0, 30, 60, 90])     # north
    circles = [p for p in track.patches if isinstance(p, Circle)]
    assert [c.radius for c in circles] == [2.51] * 3
    switched = next(line for line in track.lines if line.get_label() == "leg switched")
    assert len(switched.get_xdata()) == len(np.flatnonzero(np.diff(waves["guidance.wp_index"])))
    hulls = [p for p in track.patches if isinstance(p, Polygon)]
    assert len(hulls) >= 8
    scale = outlines(waves).scale                 # enlarged, and the legend says how much
    corners = hulls[0].get_xy()
    assert np.ptp(corners[:, 1]) == pytest.approx(scale * Hull.L)  # heading north at t = 0
    assert np.ptp(corners[:, 0]) == pytest.approx(scale * Hull.B)
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert f"ship outline x{scale}, true heading, every 30 s" in legend
    waves_to = next(line for line in track.lines if line.get_label().startswith("waves"))
    assert waves_to.get_label() == "waves travel to 180 deg"
    tip = waves_to.get_marker().vertices[0]                     # (east, north): south
    assert tip[1] == pytest.approx(-1.0) and tip[0] == pytest.approx(0.0, abs=1e-12)
    labels = [a.get_ylabel() for a in fig.axes[1:]]
    assert labels == ["surge u (m/s)", "heading (deg)", "psi_d - psi (deg)",
                      "yaw rate r (deg/s)", RUDDER_LABEL]
    rudder = [line.get_label() for line in fig.axes[-1].lines
              if not line.get_label().startswith("_")]
    assert rudder == ["commanded delta_c", "actual delta"]


def test_the_title_and_the_header_describe_the_run_that_was_made(fmu_paths, tmp_path, capsys):
    assert cli.main(["waves_pd", "--set", "ship.Hs=0.01", "--set", "ship.psi_w=1.5708",
                     "--set", "autopilot.Kd=30", "--stop-time", "60", "--out",
                     str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "waves Hs 10 mm, T0 0.8 s, travelling to 90 deg, seed 2010" in out
    assert "autopilot pd_autopilot.fmu: Kp = 2, Kd = 30 s" in out
    assert "set: --set ship.Hs=0.01 --set ship.psi_w=1.5708 --set autopilot.Kd=30" in out
    assert "5 mm" not in out and "180 deg" not in out
    assert "lambda making them equal on calm_pd" in out          # what delta_E is
    assert "60 s in steps of 0.1 s, gauss-seidel coupling, fmi backend" in out


def test_next_to_every_csv_a_json_with_what_it_takes_to_reproduce_the_run(fmu_paths,
                                                                          tmp_path):
    assert cli.main(["calm_smc", "--set", "autopilot.eta_h=5.0", "--stop-time", "20",
                     "--no-plot", "--out", str(tmp_path)]) == 0
    meta = json.loads((tmp_path / "calm_smc.json").read_text())
    header = (tmp_path / "calm_smc.csv").read_text().splitlines()[0].split(",")
    assert list(meta["columns"]) == header
    assert meta["columns"]["ship.psi"] == "rad" and meta["columns"]["autopilot.sigma"] == "1"
    assert meta["parameters"]["autopilot"]["eta_h"] == 5.0                # as set
    assert meta["parameters"]["autopilot"]["zeta"] == 0.85                # the default
    assert meta["parameter_units"]["autopilot"]["omega_n"] == "rad/s"
    assert meta["overrides"] == {"autopilot": {"eta_h": 5.0}}
    fmu = meta["fmus"]["ship"]
    assert fmu["guid"] == read_model_description(fmu["file"]).guid
    with open(fmu["file"], "rb") as f:
        assert fmu["sha256"] == hashlib.sha256(f.read()).hexdigest()
    from fmukit.manifest import read          # the one notion of a current FMU
    assert fmu["current"] is True and fmu["sources_digest"] == read(fmu["file"]).digest
    assert (meta["coupling"], meta["step_size"], meta["stop_time"], meta["rows"]) == \
        ("gauss-seidel", 0.1, 20.0, 201)
    assert meta["wall_time_s"] > 0 and meta["versions"]["ship-autopilot-cosim"] == "0.1.0"
    assert meta["error"] is None and meta["backend"] == "fmi"
    assert meta["columns"]["time"] == "s" and meta["settings"]["ship"]["n1"] == 8.13
    assert meta["scenario_sha256"] == hashlib.sha256(
        open(meta["scenario_file"], "rb").read()).hexdigest()


def test_the_imo_10_10_zigzag_is_never_checked_by_this_unstable_ship(fmu_paths, tmp_path,
                                                                     capsys):
    """With 10 deg of counter-rudder CyberShip II keeps turning; it needs 16 deg."""
    def zigzag(degrees: float):
        angle = math.radians(degrees)
        return zigzag_of(simulate("zigzag_10_10", backend="inprocess", set={
            "program.delta": angle, "program.psi_switch": angle})).figures
    assert not zigzag(10).checked
    assert not zigzag(15).checked
    z16 = zigzag(16)
    assert z16.checked
    assert math.degrees(z16.overshoots[0].angle) == pytest.approx(64.52, abs=0.01)
    assert math.degrees(z16.overshoots[1].angle) == pytest.approx(8.14, abs=0.01)
    assert cli.main(["zigzag_10_10", "--out", str(tmp_path)]) == 0
    assert "the turn was never checked: 1 rudder reversal(s) of 3" in capsys.readouterr().out
    assert (tmp_path / "zigzag_10_10.png").stat().st_size > 50_000


def test_animate_writes_a_gif_with_one_frame_per_tenth_of_a_second_of_video(fmu_paths,
                                                                           tmp_path):
    from PIL import Image

    assert len(frame_times(np.arange(1001.0))) == 250            # a 25 s video at most
    run = simulate("calm_pd", stop_time=5)
    gif = animate(run, tmp_path / "calm_pd", "calm_pd", "gif")
    with Image.open(gif) as image:
        assert image.n_frames == len(frame_times(run.t)) == 51
        assert image.info["duration"] == 100                      # 10 frames per second
    assert [p.name for p in tmp_path.iterdir()] == ["calm_pd.gif"]


def test_animate_feeds_ffmpeg_whole_frames(fmu_paths, tmp_path, monkeypatch):
    """Where ffmpeg exists: raw RGB frames on its standard input (a stand-in checks them)."""
    fake = tmp_path / "bin" / "ffmpeg"
    fake.parent.mkdir()
    fake.write_text('#!/bin/sh\nfor last; do :; done\ncat > "$last"\n')
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", f"{fake.parent}:{__import__('os').environ['PATH']}")
    run = simulate("calm_pd", stop_time=10)
    video = animate(run, tmp_path / "calm_pd", "calm_pd", "mp4")       # ffmpeg "exists"
    assert video.suffix == ".mp4"
    assert video.stat().st_size == len(frame_times(run.t)) * 900 * 504 * 3


def test_animate_refuses_a_system_without_a_track_before_running(fmu_paths, tmp_path, capsys):
    from cosim.core.ssd import Component, Connection, SystemDescription, write_ssd

    system = SystemDescription(
        "no_track", {"autopilot": Component("autopilot", str(fmu_paths["pd_autopilot"]),
                                            {"delta_c": ("output", "Real")}),
                     "pid": Component("pid", str(fmu_paths["pid_autopilot"]),
                                      {"psi": ("input", "Real")})},
        [Connection("autopilot", "delta_c", "pid", "psi")], report="none")
    write_ssd(system, tmp_path / "no_track.ssd")
    assert cli.main([str(tmp_path / "no_track.ssd"), "--animate", "--out",
                     str(tmp_path / "out")]) == 2
    assert "--animate needs the ship's track; this system records no ship.x" in \
        capsys.readouterr().err
    assert not (tmp_path / "out").exists()                  # nothing ran, nothing left


def test_a_figure_that_cannot_be_written_leaves_nothing_behind(waves, tmp_path):
    (tmp_path / "waves.png").mkdir()                # the name is taken by a folder
    with pytest.raises(OSError):
        save(course_keeping_figure(waves), tmp_path / "waves")
    assert [p.name for p in tmp_path.iterdir()] == ["waves.png"]


def test_svg_and_pdf_on_request(fmu_paths, tmp_path):
    assert cli.main(["calm_pd", "--stop-time", "20", "--figure-format", "svg",
                     "--figure-format", "pdf", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "calm_pd.svg").read_text().lstrip().startswith("<?xml")
    assert (tmp_path / "calm_pd.pdf").read_bytes()[:4] == b"%PDF"


def test_no_progress_bar_where_standard_error_is_not_a_terminal(fmu_paths, tmp_path, capsys,
                                                                monkeypatch):
    """tqdm's own test of the terminal (``disable=None``), on the command's standard error."""
    bars = []

    def bar(**options):
        bars.append((options, tqdm(**options)))
        return bars[-1][1]
    monkeypatch.setattr(cli, "tqdm", bar)
    assert cli.main(["calm_pd", "--stop-time", "10", "--no-plot", "--out", str(tmp_path)]) == 0
    ((options, made),) = bars
    assert options["file"] is sys.stderr and options["disable"] is None and made.disable
    assert "step/s" not in capsys.readouterr().err


def test_a_sweep_says_its_units_as_the_command_line_does(fmu_paths, tmp_path, scheduler):
    from cosim import sweep as sweep_cli

    spec = tmp_path / "spec.toml"
    spec.write_text('name = "units"\nstop_time = 100\n[controllers]\npd = "waves_pd"\n'
                    '[axes]\nwave_seed = [1, 2]\n[plots]\ntracks = { controller = "pd" }\n')
    assert sweep_cli.main([str(spec), "--out", str(tmp_path), "--scheduler",
                           scheduler, "--no-progress"]) == 0
    out = tmp_path / "units"
    units = json.loads((out / "results.json").read_text())["units"]
    assert units["max_delta_deg"] == "deg" and units["J"] == "rad^2"
    import pyarrow.parquet as pq
    table = pq.read_table(out / "results.parquet")
    assert table.schema.field("max_delta_deg").metadata == {b"unit": b"deg"}
    run = simulate("waves_pd", set={"ship.wave_seed": 1}, stop_time=100)
    row = table.to_pylist()[0]
    assert row["max_delta_deg"] == pytest.approx(math.degrees(np.abs(run["ship.delta"]).max()))
    assert (out / "tracks.png").stat().st_size > 20_000


def test_the_metadata_is_strict_json_when_a_value_is_not_finite(tmp_path):
    """A non-finite number in a run's metadata (no value the master sets can be one now,
    but an FMU may read one back) is written as its name, a string: strict JSON."""
    recording = Recording([], np.empty(0), np.empty((0, 0)), error="ship failed",
                          meta={"parameters": {"ship": {"Hs": math.nan, "T0": math.inf}}})
    text = write_metadata(recording, tmp_path / "run.json").read_text()
    meta = json.loads(text, parse_constant=lambda token: pytest.fail(f"{token} in JSON"))
    assert meta["parameters"]["ship"] == {"Hs": "nan", "T0": "inf"}


def test_a_run_that_loses_the_ship_says_so(fmu_paths, tmp_path, capsys):
    assert cli.main(["waves_pd", "--set", "ship.Hs=0.01", "--set", "ship.psi_w=1.5708",
                     "--no-plot", "--out", str(tmp_path)]) == 0
    assert "warning: the rudder was at its stops for" in capsys.readouterr().out


def test_a_run_given_the_route_as_numbers_describes_and_draws_that_route(fmu_paths, tmp_path,
                                                                          capsys):
    """An exported package's .ssd gives the route as numbers (for tools without String
    parameters): the report and the figure show that route, not the String's default."""
    import zipfile

    from cosim.interop.ssp import export
    south = "0,0;30,0;60,-25;90,-25"
    package = export("calm_pd", tmp_path, {"guidance": {"waypoints": south}})
    zipfile.ZipFile(package).extractall(tmp_path / "package")
    assert cli.main([str(tmp_path / "package" / "SystemStructure.ssd"), "--stop-time", "10",
                     "--out", str(tmp_path / "out")]) == 0
    assert "route (0,0) (30,0) (60,-25) (90,-25) m" in capsys.readouterr().out
    run = simulate(tmp_path / "package" / "SystemStructure.ssd", stop_time=10.0)
    fig = course_keeping_figure(run)
    route = [line for line in fig.axes[0].get_lines() if line.get_label().startswith("route")][0]
    assert list(route.get_xdata()) == [0, 0, -25, -25]      # east y of each point
