"""The master: exchanged signals, equality with the plain modules, couplings, bad input."""
from __future__ import annotations

import math
import re
import shutil
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from autopilot_fmu.guidance import parse_waypoints
from autopilot_fmu.pd import PDAutopilot
from cosim import run as cli
from cosim import scenarios
from cosim.analysis.metrics import LAMBDA, cost_terms
from cosim.core.fmi import FmuInstance
from cosim.core.master import Master
from cosim.core.ssd import write_ssd
from cosim.core.wiring import WiringError
from cosim.ensemble.reference import SIGNALS, run_direct
from fmubuild import project
from fmubuild.project import ROOT
from helpers import fmu_variant, recorded

SCENARIOS = scenarios.SCENARIO_DIR
PAPER = ["calm_pd", "calm_smc", "waves_pd", "waves_smc"]


def system(name: str):
    return scenarios.load(name)


def run(name: str, coupling: str = "gauss-seidel", backend: str = "fmi", **kwargs):
    """A recorded run, cached for the session (``helpers.recorded``)."""
    return recorded(name, coupling=coupling, backend=backend, **kwargs)


@pytest.fixture(scope="module", autouse=True)
def fmus_built(fmu_paths):
    return fmu_paths


# -- what travels along the connections ---------------------------------------------
def run_reading_inputs_back(monkeypatch, coupling: str):
    """calm_pd's run, each input the master sets read back from its FMU at once: as sent."""
    writer = FmuInstance.writer

    def checked_writer(instance: FmuInstance, vrs: list[int]):
        write, read_back = writer(instance, vrs), instance.reader(vrs)

        def write_and_check(values) -> None:
            write(values)
            assert read_back() == list(values), (instance.name, vrs)
        return write_and_check
    monkeypatch.setattr(FmuInstance, "writer", checked_writer)
    with Master(system("calm_pd"), coupling=coupling) as master:
        rec = master.run()
    assert rec.error is None, rec.error
    return rec


def test_gauss_seidel_signals_arrive_unchanged_and_in_step(monkeypatch):
    rec = run_reading_inputs_back(monkeypatch, "gauss-seidel")
    assert rec.rows == 4001 and rec.t[-1] == 400.0
    np.testing.assert_array_equal(rec["ship.delta_c"], rec["autopilot.delta_c"])
    np.testing.assert_array_equal(rec["autopilot.psi"], rec["ship.psi"])
    np.testing.assert_array_equal(rec["autopilot.r"], rec["ship.r"])
    np.testing.assert_array_equal(rec["autopilot.psi_d"], rec["guidance.psi_d"])
    np.testing.assert_array_equal(rec["guidance.x"], rec["ship.x"])
    pd = PDAutopilot()
    sent = [pd.command(p, r, d) for p, r, d in
            zip(rec["ship.psi"], rec["ship.r"], rec["guidance.psi_d"])]
    np.testing.assert_array_equal(rec["autopilot.delta_c"], sent)


def test_jacobi_autopilot_answers_the_inputs_of_the_previous_step(monkeypatch):
    rec = run_reading_inputs_back(monkeypatch, "jacobi")
    np.testing.assert_array_equal(rec["ship.delta_c"], rec["autopilot.delta_c"])
    pd = PDAutopilot()
    sent = [pd.command(p, r, d) for p, r, d in
            zip(rec["autopilot.psi"], rec["autopilot.r"], rec["autopilot.psi_d"])]
    np.testing.assert_array_equal(rec["autopilot.delta_c"][1:], sent[:-1])


def test_psi_d_is_eq_18_of_the_active_leg():
    rec = run("calm_pd")
    points = parse_waypoints(system("calm_pd").components["guidance"].parameters["waypoints"])
    legs = np.minimum(rec["guidance.wp_index"].astype(int), len(points) - 1)
    expected = [math.atan2(points[k][1] - points[k - 1][1], points[k][0] - points[k - 1][0])
                for k in legs]
    np.testing.assert_array_equal(rec["guidance.psi_d"], expected)
    assert set(rec["guidance.wp_index"]) == {1.0, 2.0, 3.0, 4.0}   # the whole route


# -- equality with the plain modules ---------------------------------------------------
@pytest.mark.parametrize("name", PAPER)
def test_cosimulation_equals_the_plain_modules_wired_by_hand(name):
    with Master(system(name), backend="inprocess") as master:
        rec, direct = run(name), run_direct(master)
    worst = max(np.abs(rec[s] - direct[s]).max() for s in SIGNALS)
    assert worst <= 1e-9


@pytest.mark.parametrize("name", scenarios.names())
def test_fmi_and_inprocess_backends_agree_bit_for_bit(name):
    """Every column of every row, and the parameters the FMUs report."""
    couplings = ("gauss-seidel", "jacobi") if name == "waves_smc" else ("gauss-seidel",)
    for coupling in couplings:
        fmi, inprocess = (run(name, coupling, backend) for backend in ("fmi", "inprocess"))
        assert fmi.columns == inprocess.columns and fmi.rows == inprocess.rows > 1000
        assert np.array_equal(fmi.t, inprocess.t)
        assert np.array_equal(fmi.data, inprocess.data), [
            c for i, c in enumerate(fmi.columns)
            if not np.array_equal(fmi.data[:, i], inprocess.data[:, i])]
        assert fmi.meta["parameters"] == inprocess.meta["parameters"]
        assert set(inprocess.meta["backends"].values()) == {"inprocess"}, inprocess.meta["notes"]


def test_only_fmus_current_in_this_process_run_in_process(fmu_paths, tmp_path, monkeypatch):
    from cosim.core.inprocess import in_process_refusal
    from fmubuild.packaging import build_script

    ship = fmu_paths["ship"]
    assert in_process_refusal(ship) is None
    # by content, whatever the file's name (a sweep's worker names them by hash)
    assert in_process_refusal(shutil.copy(ship, tmp_path / "0a1b2c.fmu")) is None
    edited = fmu_variant(ship, tmp_path / "edited.fmu", edit={
        "resources/ship_fmu/hull.py": lambda text: text + "\n# changed\n"})
    assert in_process_refusal(edited) == "its ship_fmu/hull.py is not the source its manifest lists"
    renamed = fmu_variant(ship, tmp_path / "renamed.fmu",
                          lambda xml: xml.replace('name="delta_c"', 'name="rudder"'))
    assert in_process_refusal(renamed) == ("its ModelVariables differ from those its class "
                                           "ship_fmu.ship_slave.ShipSlave declares")
    other = fmu_variant(ship, tmp_path / "other.fmu",
                        lambda xml: xml.replace('modelName="ship"', 'modelName="tanker"'))
    assert in_process_refusal(other) == ("its model description names the model 'tanker', its "
                                         "manifest 'ship'")
    extra = tmp_path / "extra.fmu"
    shutil.copy(fmu_paths["pid_autopilot"], extra)
    with zipfile.ZipFile(extra, "a") as fmu:
        fmu.writestr("resources/tuning.py", "GAIN = 0.5\n")
    assert in_process_refusal(extra) == "it carries tuning.py, which its manifest does not list"
    assert in_process_refusal(fmu_paths["pd_autopilot_c"]) == ("it was not built with fmukit "
                                                               "(it has no manifest)")
    # a user's FMU built with fmukit qualifies too, where its sources are importable (not
    # an FMU's copy that a run in this process imported before: pythonfmu runs an FMU's
    # Python in its host's interpreter)
    monkeypatch.delitem(sys.modules, "my_pid", raising=False)
    script = shutil.copy(ROOT / "autopilot_fmu" / "pid_autopilot_slave.py", tmp_path / "my_pid.py")
    mine = build_script(Path(script), ("fmukit",), tmp_path / "out" / "my_pid.fmu")
    assert in_process_refusal(mine) == "its module my_pid is not importable here"
    monkeypatch.syspath_prepend(str(tmp_path))
    assert in_process_refusal(shutil.copy(mine, tmp_path / "mine.fmu")) is None
    Path(script).write_text(Path(script).read_text() + "\n# tuned\n")
    assert in_process_refusal(shutil.copy(mine, tmp_path / "tuned.fmu")).startswith(
        f"its my_pid differs from {script} (built before a change: rebuild it)")
    master = Master(system("calm_pd"), backend="inprocess")
    try:
        assert master.backends == dict.fromkeys(["guidance", "autopilot", "ship"], "inprocess")
        assert master.notes == []
    finally:
        master.free()


@pytest.mark.parametrize("overrides", [      # what only the FMU can judge (a value out of
    {"guidance": {"waypoints": "0,0;nan,1"}},   # its declared range the master refuses first:
    {"ship": {"Hs": 0.1, "T0": 0.2}}])          # tests/test_values.py)
def test_inprocess_backend_refuses_what_the_fmus_refuse_with_their_words(overrides):
    errors = []
    for backend in ("fmi", "inprocess"):
        master = Master(system("calm_pd"), backend=backend, overrides=overrides)
        try:
            errors.append(master.run(5.0).error)
        finally:
            master.free()
    name, value = next(iter(next(iter(overrides.values())).items()))
    assert f"{name} = {value}" in errors[0] or f"{name}: " in errors[0], errors[0]
    assert errors[0] == errors[1]


# -- coupling orders ------------------------------------------------------------------------
def _first_rudder_step(rec) -> int:
    return int(np.argmax(np.abs(rec["ship.delta_c"]) > 0.0))


def test_jacobi_delays_the_rudder_one_step_per_feedthrough_fmu():
    """Rudder answers the heading one step later, a course change two (guidance, autopilot)."""
    gs, jac = run("waves_pd"), run("waves_pd", coupling="jacobi")
    assert _first_rudder_step(jac) - _first_rudder_step(gs) == 1       # heading feedback
    gs, jac = run("calm_pd"), run("calm_pd", coupling="jacobi")
    assert _first_rudder_step(jac) - _first_rudder_step(gs) == 2       # course change
    assert np.degrees(np.abs(gs["ship.psi"] - jac["ship.psi"]).max()) < 0.5


def test_gauss_seidel_order_follows_the_signal_flow():
    master = Master(system("calm_smc"))
    try:
        assert master.order == ["guidance", "autopilot", "ship"]
    finally:
        master.free()


# -- lambda and the reports ------------------------------------------------------------------
def test_lambda_is_calibrated_on_calm_pd():
    rec = run("calm_pd")
    psi_E, sum_delta2 = cost_terms(rec["guidance.psi_d"], rec["ship.psi"], rec["ship.delta"])
    assert LAMBDA == pytest.approx(psi_E / sum_delta2, rel=1e-9)


def test_run_writes_every_signal_and_a_figure(tmp_path, capsys):
    assert cli.main(["calm_smc", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for word in ("psi_E", "sum delta^2", "lambda", "J ="):
        assert word in out
    header, *rows = (tmp_path / "calm_smc.csv").read_text().splitlines()
    columns = header.split(",")
    assert len(rows) == 4001 and {"autopilot.psi_z", "ship.delta", "guidance.psi_d",
                                  "ship.delta_c", "ship.X_w"} <= set(columns)
    assert (tmp_path / "calm_smc.png").stat().st_size > 10_000


def test_all_prints_tables_1_and_2_beside_the_paper(tmp_path, capsys):
    assert cli.main(["--all", "--out", str(tmp_path), "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert "Table 1, calm water" in out and "Table 2, waves" in out
    assert "256.94" in out and "390.55" in out          # the paper's J for PD calm, SMC waves
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(PAPER)
    # the published tables (README, docs/reproduction.md) are what the code computes today,
    # and the paper's columns beside them are the paper's
    printed = re.findall(r"^  (?:PD|SMC) controller +([\d.]+) +([\d.]+) +([\d.]+) +\| +"
                         r"([\d.]+) +([\d.]+) +([\d.]+)", out, re.M)
    assert len(printed) == 4
    for page in (ROOT / "README.md", ROOT / "docs" / "reproduction.md"):
        cells = re.findall(r"^\| (?:PD|SMC) controller" + r" \| ([^|]+)" * 6 + r" \|",
                           page.read_text(), re.M)
        assert len(cells) == 4, page
        for published, ours in zip(cells, printed):
            for cell, value in zip(published, ours):
                _check_published(cell, value)


def _check_published(cell: str, value: str) -> None:
    """'201.56' equals the printed value; '201.56 ± 1.77' is the run's value and how far one
    last bit moves it (cosim.run --all --spread): the value printed on this CPU, or on one
    whose C library rounds a sin differently, lies within it."""
    number, change = re.fullmatch(r"([\d.]+)(?: ± ([\d.]+))?", cell.strip()).groups()
    if change is None:
        assert number == value
    else:
        assert abs(float(value) - float(number)) <= float(change), (cell, value)


def test_the_spread_of_a_run_is_how_far_a_last_bit_moves_it(capsys):
    """Calm water amplifies no last bit; the chattering SMC in waves does, within 60 s."""
    from cosim.studies.cpu_variants import nudged, spread

    assert nudged(0.3, 2) == math.nextafter(math.nextafter(0.3, 1.0), 1.0)
    assert nudged(math.pi, -1) == math.nextafter(math.pi, 0.0)
    calm = spread(system("calm_pd"), ulps=1, stop_time=60.0)
    assert calm.runs == 5 and calm.describe() == "every figure as printed"
    waves = spread(system("waves_smc"), ulps=1, stop_time=60.0)
    assert waves.runs == 5 and max(waves.deviation.values()) > 0.0
    assert all(waves.nominal[f] - waves.deviation[f] > 0.0 for f in ("psi_E", "J"))
    with pytest.raises(SystemExit):
        cli.main(["calm_pd", "--spread", "0"])
    assert "--spread takes a number of ulps >= 1, got 0" in capsys.readouterr().err


def test_stop_time_and_set_reach_the_fmus(tmp_path):
    assert cli.main(["calm_pd", "--out", str(tmp_path), "--no-plot", "--stop-time", "20",
                     "--set", "ship.Hs=0.004", "--set", "ship.wave_seed=3"]) == 0
    header, *rows = (tmp_path / "calm_pd.csv").read_text().splitlines()
    assert len(rows) == 201
    X_w = [float(r.split(",")[header.split(",").index("ship.X_w")]) for r in rows]
    assert max(map(abs, X_w)) > 0.1


def test_manoeuvre_scenarios_report_their_figures(tmp_path, capsys):
    assert cli.main(["zigzag_20_20", "--out", str(tmp_path), "--no-plot"]) == 0
    assert "first overshoot 31.66 deg, second overshoot 7.25 deg" in capsys.readouterr().out


# -- bad input ---------------------------------------------------------------------------
def test_unknown_scenario_lists_the_valid_ones(capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["calm_xyz"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "unknown scenario 'calm_xyz'" in err and "waves_smc" in err


def test_a_misspelt_scenario_gets_the_names_it_could_mean(capsys):
    with pytest.raises(SystemExit):
        cli.main(["Waves_SMC"])
    assert capsys.readouterr().err.rstrip().endswith("did you mean 'waves_smc' or 'waves_pd'?")


def _variant(tmp_path: Path, name: str, edit) -> Path:
    description = system(name)
    edit(description)
    path = tmp_path / f"{name}.ssd"
    sources = {c: str(description.fmu_path(c)) for c in description.components}
    sources.update({c: comp.source for c, comp in description.components.items()
                    if not comp.source.startswith("../../fmus")})
    write_ssd(description, path, sources)
    return path


def test_missing_fmu_names_the_paths_tried_and_says_how_to_build_it(tmp_path, monkeypatch,
                                                                    capsys):
    """The core says what is missing and that it is ours (as data); the command says how
    to build it."""
    monkeypatch.setattr(project, "FMU_DIRS", {2: tmp_path / "empty", 3: tmp_path / "fmi3"})

    def edit(d):                        # relative: beside the .ssd, then by name
        d.components["ship"].source = "nowhere/ship.fmu"
    with pytest.raises(FileNotFoundError, match="one of this project's FMUs, not built") as missing:
        Master(scenarios.load(_variant(tmp_path, "calm_pd", edit)))
    beside = (SCENARIOS / "nowhere" / "ship.fmu").resolve()
    assert f"tried {beside}, {tmp_path / 'empty' / 'ship.fmu'}" in str(missing.value)
    assert missing.value.ours and "python -m" not in str(missing.value)
    variant = tmp_path / "calm_pd.ssd"
    variant.write_text((SCENARIOS / "calm_pd.ssd").read_text().replace(
        "../../fmus/ship.fmu", str(tmp_path / "nowhere" / "ship.fmu")))
    assert cli.main([str(variant), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "not found" in err and "one of this project's FMUs, not built\n" \
        "  build the FMUs with: python -m fmukit.build" in err


def test_a_missing_fmu_of_the_user_is_not_a_build_problem(tmp_path):
    def edit(d):
        d.components["autopilot"].source = "my_pilot.fmu"
    with pytest.raises(FileNotFoundError, match="check the source of component 'autopilot'"):
        Master(scenarios.load(_variant(tmp_path, "calm_pd", edit)))


def test_a_scenario_copied_anywhere_finds_the_project_fmus(tmp_path):
    copy = tmp_path / "elsewhere" / "my_calm_pd.ssd"
    copy.parent.mkdir()
    shutil.copy(SCENARIOS / "calm_pd.ssd", copy)      # sources still say ../../fmus/*.fmu
    assert cli.main([str(copy), "--out", str(tmp_path), "--no-plot", "--stop-time", "10"]) == 0
    assert len((tmp_path / "my_calm_pd.csv").read_text().splitlines()) == 102


def test_corrupt_fmu_says_how_to_build_it(tmp_path):
    corrupt = tmp_path / "ship.fmu"
    corrupt.write_bytes(b"PK\x03\x04 this is not an FMU")

    def edit(d):
        d.components["ship"].source = str(corrupt)
    with pytest.raises(ValueError, match="not a readable FMU") as unreadable:
        Master(scenarios.load(_variant(tmp_path, "calm_pd", edit)))
    assert unreadable.value.ours


def test_connection_to_a_missing_variable_is_refused_by_name(tmp_path):
    def edit(d):
        d.connections[0] = type(d.connections[0])("guidance", "psi_desired", "autopilot", "psi_d")
    with pytest.raises(WiringError, match="guidance.psi_desired.*no variable 'psi_desired'"):
        Master(scenarios.load(_variant(tmp_path, "calm_pd", edit)))


def test_unwritable_output_folder_is_refused_before_simulating(tmp_path, monkeypatch, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("")

    def no_simulation(*args, **kwargs):
        raise AssertionError("simulated although the output folder is unusable")
    monkeypatch.setattr(cli, "run_and_write", no_simulation)
    with pytest.raises(SystemExit) as refused:
        cli.main(["calm_pd", "--out", str(blocker / "results")])
    assert refused.value.code == 2 and "not writable" in capsys.readouterr().err


@pytest.mark.parametrize("stream", [[], ["--stream"]])
def test_fmu_error_mid_run_names_fmu_call_and_time_and_keeps_the_rows(tmp_path, monkeypatch,
                                                                      capsys, stream):
    from ship_fmu.vessel import Vessel
    step = Vessel.step

    def failing_step(self, t, h, delta_c, *args):
        if t >= 50.0:
            raise ValueError("injected fault")
        return step(self, t, h, delta_c, *args)
    monkeypatch.setattr(Vessel, "step", failing_step)
    code = cli.main(["calm_pd", "--out", str(tmp_path), "--backend", "inprocess", *stream])
    assert code == 1
    err = capsys.readouterr().err
    assert "FMU 'ship': doStep at t = 50 s" in err and "injected fault" in err
    assert "the 500 rows recorded before the error" in err
    header, *rows = (tmp_path / "calm_pd.csv").read_text().splitlines()
    assert len(rows) == 500 and rows[-1].startswith("49.9")


def test_streamed_rows_equal_the_in_memory_recording(tmp_path, monkeypatch):
    """Rows written in chunks as the run goes are the rows a whole recording writes."""
    monkeypatch.setattr("cosim.core.recording.CHUNK_ROWS", 64)
    master = Master(system("waves_smc"))
    try:
        whole = master.run(30.0)
        master.reset()
        streamed = master.run(30.0, csv_path=tmp_path / "streamed.csv")
    finally:
        master.free()
    whole.write_csv(tmp_path / "whole.csv")
    assert streamed.rows == 301 and streamed.path == tmp_path / "streamed.csv"
    with pytest.raises(ValueError, match="streamed to"):
        streamed["ship.psi"]                # the rows are in the file, not in memory
    assert (tmp_path / "streamed.csv").read_text() == (tmp_path / "whole.csv").read_text()


def test_the_overhead_benchmark_runs_and_restores_the_ship(fmu_paths, capsys):
    """A smoke test of one benchmark (figures are printed, never asserted): it idles the
    ship's step while it measures, and must give it back."""
    from cosim.studies import timing
    from ship_fmu.vessel import Vessel

    step = Vessel.step
    per_step = timing.overhead(1)
    assert Vessel.step is step
    assert set(per_step) == {"direct", "idle", "inprocess"}
    out = capsys.readouterr().out
    assert "the in-process master beyond the modules wired by hand:" in out
    assert re.search(r"on .+ \(family \d+, model \d+, (no )?AVX-512\), \d+ cores, .+; load "
                     r"average [\d.]+ [\d.]+ [\d.]+", out), out
