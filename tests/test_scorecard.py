"""The scorecard: your autopilot beside PD, SMC and PID, on every criterion, in tables and
figures."""
from __future__ import annotations

import inspect
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from cosim import score as cli
from cosim import simulate
from cosim.analysis.metrics import cost
from cosim.studies import scorecard_report
from cosim.studies.merit import CRITERIA

MINE = ["--set", "autopilot.Kp=1", "--set", "autopilot.Kd=30"]
"""The PD with other gains: on the paper's route in waves it moves the rudder less and
reaches fewer waypoints than the PD, so it wins some criteria and loses others."""


def _rows(text: str, heading: str) -> dict[str, list[str]]:
    """The rows of the first markdown table after ``heading``, by their first cell."""
    blocks = text[text.index(heading):].split("\n\n")
    table = next(block for block in blocks if block.startswith("|")).splitlines()[2:]
    return {cells[0]: cells[1:] for cells in
            ([c.strip() for c in row.strip("|").split("|")] for row in table)}


def _journal(folder) -> list[dict]:
    return [json.loads(line) for line in (folder / "runs.jsonl").read_text().splitlines()]


def _expected(criterion, rows: list[dict], name: str) -> str:
    """'won W, lost L, tied T of N', counted here from the journal's rows, seed by seed."""
    value = {(r["controller"], r["wave_seed"]): r[criterion.column] for r in rows}
    seeds = sorted({r["wave_seed"] for r in rows})
    won = lost = tied = 0
    for seed in seeds:
        mine, pd = value[name, seed], value["PD", seed]
        if abs(mine - pd) <= 0.01 * abs(pd):
            tied += 1
        elif (mine < pd) == criterion.lower_is_better:
            won += 1
        else:
            lost += 1
    return f"won {won}, lost {lost}, tied {tied} of {len(seeds)}"


def _reached(csv) -> int:
    """Waypoints of the paper's route the track of a run's CSV came within 2.51 m of."""
    data = np.genfromtxt(csv, delimiter=",", names=True)
    return sum(np.hypot(data["shipx"] - x, data["shipy"] - y).min() <= 2.51
               for x, y in [(0, 0), (30, 0), (60, 25), (90, 25)])


def _sketch(monkeypatch) -> set[str]:
    """The scorecard's figure functions replaced by stand-ins that check their arguments
    against the real functions' signatures and write a placeholder; the names written."""
    from cosim.studies import scorecard

    written = set()

    def stand_in(real, path_at):
        def sketch(*args, **kwargs):
            inspect.signature(real).bind(*args, **kwargs)
            if path_at is not None:
                Path(args[path_at]).write_bytes(b"figure")
                written.add(Path(args[path_at]).stem)
            return args
        return sketch
    for name, path_at in (("comparison", None), ("save", 1), ("distribution", 2),
                          ("paired_figure", 3), ("tracks", 2)):
        monkeypatch.setattr(scorecard, name, stand_in(getattr(scorecard, name), path_at))
    return written


@pytest.mark.parametrize("drawn", [False, pytest.param(True, marks=pytest.mark.long)])
def test_the_scorecard_names_the_criteria_each_autopilot_wins_and_loses(fmu_paths, tmp_path,
                                                                        capsys, scheduler,
                                                                        monkeypatch, drawn):
    """The quick suite checks what the figures are given; --long draws them."""
    sketched = None if drawn else _sketch(monkeypatch)
    out = tmp_path / "score"
    assert cli.main([str(fmu_paths["pd_autopilot"]), "--name", "mine", *MINE, "--seeds", "2",
                     "--scheduler", scheduler, "--out", str(out), "--backend", "inprocess"]) == 0
    text = (out / "scorecard.md").read_text()
    assert text in capsys.readouterr().out
    assert "`pd_autopilot.fmu` ran in the scorecard's processes (not isolated)." in text
    # results up front: per sea, every criterion with its side, each controller's verdict
    for sea, folder in (("the paper's waves", "ensemble"),
                        ("wind and current", "ensemble_wind_current"),
                        ("a steering-gear pump failure", "ensemble_pump_failure")):
        glance = _rows(text, f"The route in {sea}")
        rows = _journal(out / folder)
        assert len(rows) == 8 and all(r["status"] == "ok" for r in rows)
        assert list(glance) == [c.label + (f" ({c.unit})" if c.unit else "") for c in CRITERIA]
        for criterion, cells in zip(CRITERIA, glance.values()):
            assert cells[0] == criterion.better.split()[0]
            for name, cell in zip(("SMC", "PID", "mine"), cells[1:]):
                assert _expected(criterion, rows, name) in cell, (sea, criterion.label, name)
                assert cell.split(":")[0].strip("*") in ("better", "worse", "even", "mixed")
    glance = _rows(text, "The route in the paper's waves")
    verdicts = {label: cells[3].split(":")[0].strip("*") for label, cells in glance.items()}
    assert "better" in verdicts.values() and "worse" in verdicts.values()   # no single rank
    # route completion in every test that follows the route, plainly
    completion = _rows(text, "Route completion")
    assert list(completion) == ["PD", "SMC", "PID", "mine"]
    for name, cells in completion.items():
        for sea, cell in zip(("calm", "waves"), cells):
            assert cell.startswith(f"reached {_reached(out / 'runs' / f'route_{sea}_{name}.csv')}"
                                   " of 4 waypoints")
        heavy = [r for r in _journal(out / "ensemble_wind_current") if r["controller"] == name]
        if not any(r["last_waypoint_reached"] for r in heavy):
            assert f"**{name} never reached the last waypoint** in any of 2 seeds" in text
    # the tables beside the paper's, and the course change
    route = _rows(text, "## The paper's route")
    assert route["PD"][-1] == "256.9 / 520.8" and route["mine"][-1] == "-"
    calm_pd = cost(simulate("calm_pd", backend="inprocess")).J
    assert route["PD"][2] == f"{calm_pd:.1f}"
    change = _rows(text, "## A 40 deg course change")
    assert float(change["PD"][0]) < float(change["SMC"][0])  # the PD settles faster
    for sea in ("the paper's waves", "wind and current", "a steering-gear pump failure"):
        spread = _rows(text, f"## Wave ensemble: the route in {sea}")
        assert [cells[0] for cells in spread.values()] == ["2/2"] * 4
        assert "median [IQR, 25-75 %]" in text
    for figure in ("route_calm", "route_waves", "course_change", *(
            f"{kind}_{sea}" for kind in ("criteria", "paired", "tracks")
            for sea in ("waves", "wind_current", "pump_failure"))):
        assert (out / f"{figure}.png").stat().st_size > 10_000 if drawn else figure in sketched
        assert f"({figure}.png)" in text
    # each run's signals and metadata, written as cosim.run writes them
    runs = sorted(p.name for p in (out / "runs").iterdir())
    assert runs == sorted(f"{test}_{name}.{suffix}" for test in ("route_calm", "route_waves",
                                                                    "course_change")
                          for name in ("PD", "SMC", "PID", "mine") for suffix in ("csv", "json"))


def _row(controller: str, seed: int, **values) -> dict:
    """A journal row as a sweep writes it (each run its own id)."""
    return {"run_id": f"{controller}-{seed}", "controller": controller, "wave_seed": seed,
            "status": "ok", **values}


def test_a_win_is_the_better_value_on_the_same_sea_and_a_tie_within_one_percent():
    J, waypoints = CRITERIA[0], next(c for c in CRITERIA if c.column == "waypoints_reached")
    assert J.lower_is_better and not waypoints.lower_is_better
    rows = [_row("PD", 1, J=100.0, waypoints_reached=3.0),
            _row("PD", 2, J=200.0, waypoints_reached=3.0),
            _row("PD", 3, J=300.0, waypoints_reached=3.0),
            _row("mine", 1, J=90.0, waypoints_reached=4.0),     # better on both
            _row("mine", 2, J=201.0, waypoints_reached=3.0),    # within 1 %: a tie; equal
            _row("mine", 3, J=330.0, waypoints_reached=2.0),    # worse on both
            _row("mine", 4, J=1.0, waypoints_reached=4.0),      # no PD run on seed 4
            {**_row("PD", 4, J=1.0), "status": "failed"}]
    p = scorecard_report.paired(J, rows, "mine")
    assert (p.wins, p.losses, p.ties, p.seeds) == (1, 1, 1, 3)
    assert p.median == pytest.approx(1.005) and p.verdict == "mixed"
    q = scorecard_report.paired(waypoints, rows, "mine")
    assert (q.wins, q.losses, q.ties) == (1, 1, 1) and q.median == 0.0
    better = scorecard_report.paired(J, [r for r in rows if r["wave_seed"] != 3], "mine")
    assert (better.wins, better.losses, better.ties, better.verdict) == (1, 0, 1, "better")
    assert scorecard_report.Paired(3, 1, 0, math.nan).verdict == "better"
    # issue 40: a one-sided record is never "even", however many ties
    assert scorecard_report.Paired(0, 8, 12, math.nan).verdict == "worse"
    assert scorecard_report.Paired(1, 0, 19, math.nan).verdict == "better"
    assert scorecard_report.Paired(0, 0, 20, math.nan).verdict == "even"
    assert scorecard_report.Paired(5, 4, 11, math.nan).verdict == "mixed"
    assert scorecard_report.Paired(11, 4, 5, math.nan).verdict == "better"


def test_the_spread_of_a_criterion_over_decades_is_drawn_on_a_log_scale(tmp_path,
                                                                       monkeypatch):
    from cosim.studies import sweep_figures
    from cosim.studies.sweep_spec import Spec

    drawn = {}
    monkeypatch.setattr(sweep_figures, "save", lambda fig, path: drawn.setdefault("fig", fig)
                        and [path])
    spec = Spec(name="decades", controllers={"PD": {}, "SMC": {}},
                axes={"wave_seed": [1, 2, 3]})
    rows = [_row("PD", s, J=200.0 + s, waypoints_reached=3.0, waypoints=4.0) for s in (1, 2, 3)]
    rows += [_row("SMC", s, J=9000.0 + s, waypoints_reached=2.0, waypoints=4.0)
             for s in (1, 2, 3)]
    counted = next(c for c in CRITERIA if c.out_of)
    sweep_figures.distribution(spec, rows, tmp_path / "c.png", [CRITERIA[0], counted])
    J, waypoints = drawn["fig"].axes[:2]
    assert J.get_yscale() == "log" and "log scale" in J.get_ylabel()
    assert waypoints.get_yscale() == "linear" and "(of 4)" in waypoints.get_ylabel()
    assert [t.get_text() for t in J.get_xticklabels()] == ["PD\n202.0", "SMC\n9002.0"]
    assert "median and IQR (25-75 %)" in drawn["fig"]._suptitle.get_text()


def test_the_scorecard_refuses_a_file_that_is_not_an_autopilot(tmp_path, capsys):
    junk = tmp_path / "junk.fmu"
    junk.write_text("no")
    with pytest.raises(SystemExit) as refused:
        cli.main([str(junk), "--out", str(tmp_path / "score")])
    assert refused.value.code == 2
    assert re.search(r"junk\.fmu is not an FMU", capsys.readouterr().err)
    assert not (tmp_path / "score").exists()


def test_the_scorecard_refuses_a_name_that_is_a_baseline_s(fmu_paths, tmp_path, capsys):
    with pytest.raises(SystemExit):
        cli.main([str(fmu_paths["pd_autopilot"]), "--name", "PD", "--out", str(tmp_path / "s")])
    assert "your autopilot's name 'PD' is one of the baselines' (PD, SMC, PID)" in \
        capsys.readouterr().err
    assert not (tmp_path / "s").exists()


@pytest.mark.long    # the quick suite: the scorecard of an autopilot that works, above
def test_an_autopilot_that_fails_is_scored_as_failed_and_the_rest_goes_on(tmp_path, capsys,
                                                                         faulty_fmu, scheduler):
    failing = faulty_fmu("idle_pilot")
    out = tmp_path / "score"
    assert cli.main([str(failing), "--set", "autopilot.fail_time=150", "--seeds", "1",
                     "--scheduler", scheduler, "--out", str(out), "--backend", "inprocess"]) == 0
    err = capsys.readouterr().err
    assert ("note: controller 'idle_pilot': autopilot (idle_pilot.fmu) runs through FMI, not "
            "in-process: its module idle_pilot_slave is not importable here") in err
    assert err.count("note:") == 1
    text = (out / "scorecard.md").read_text()
    assert "`idle_pilot.fmu` ran in a process of its own (isolated)" in text   # foreign
    assert _rows(text, "## The paper's route")["idle_pilot"][:6] == ["failed"] * 6
    assert _rows(text, "## A 40 deg course change")["idle_pilot"] == ["failed"] * 6
    assert _rows(text, "## Wave ensemble: the route in the paper's")["idle_pilot"][0] == "0/1"
    assert _rows(text, "Route completion")["idle_pilot"] == ["failed", "failed", "no run ok",
                                                             "no run ok"]
    assert all(cells[-1] == "no seed ran for both"
               for cells in _rows(text, "The route in the paper's waves").values())
    assert "- idle_pilot, calm water: `FMU 'autopilot': doStep at t = 150 s returned " \
           "fatal`" in text
    calm_pd = cost(simulate("calm_pd", backend="inprocess")).J      # the others still run
    assert _rows(text, "## The paper's route")["PD"][2] == f"{calm_pd:.1f}"


def test_a_scorecard_left_without_workers_says_so_and_exits_3(fmu_paths, tmp_path, capsys,
                                                              monkeypatch):
    from cosim.studies.cluster import NoWorkers

    def no_workers(*args, **kwargs):
        raise NoWorkers("no worker in the cluster for 60 s (none has joined since 12:00:00)")
    monkeypatch.setattr(cli, "score", no_workers)
    assert cli.main([str(fmu_paths["pd_autopilot"]), "--out", str(tmp_path / "s")]) == 3
    assert "no worker in the cluster for 60 s (none has joined since 12:00:00): no " \
           "scorecard written" in capsys.readouterr().err
