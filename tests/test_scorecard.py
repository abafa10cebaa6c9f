"""The scorecard: your autopilot beside PD, SMC and PID, in tables and figures."""
from __future__ import annotations

import re

from cosim import score as cli
from cosim import simulate
from cosim.analysis.cost import cost


def _rows(text: str, heading: str) -> dict[str, list[str]]:
    """The rows of the first markdown table after ``heading``, by their first cell."""
    table = text[text.index(heading):].split("\n\n")[1].splitlines()[2:]
    return {cells[0]: cells[1:] for cells in
            ([c.strip() for c in row.strip("|").split("|")] for row in table)}


def test_the_scorecard_ranks_an_autopilot_beside_the_three_baselines(fmu_paths, tmp_path,
                                                                     capsys):
    out = tmp_path / "score"
    assert cli.main([str(fmu_paths["pid_autopilot"]), "--name", "mine", "--seeds", "2",
                     "--workers", "1", "--out", str(out)]) == 0
    text = (out / "scorecard.md").read_text()
    assert text in capsys.readouterr().out
    route = _rows(text, "## The paper's route")
    change = _rows(text, "## A 40 deg course change")
    waves = _rows(text, "## Wave ensemble")
    for table in (route, change, waves):
        assert list(table) == ["PD", "SMC", "PID", "mine"]
        assert table["mine"][:4] == table["PID"][:4]        # the same FMU, the same numbers
    assert route["PD"][-1] == "256.9 / 520.8" and route["mine"][-1] == "-"
    assert float(change["PD"][0]) < float(change["SMC"][0])  # the PD settles faster
    assert waves["mine"][-1] == "2/2"
    for figure in ("route_calm", "route_waves", "course_change", "J_distribution"):
        assert (out / f"{figure}.png").stat().st_size > 10_000
        assert f"({figure}.png)" in text
    # each run's signals and metadata, written as cosim.run writes them
    runs = sorted(p.name for p in (out / "runs").iterdir())
    assert runs == sorted(f"{test}_{name}.{suffix}" for test in ("route_calm", "route_waves",
                                                                    "course_change")
                          for name in ("PD", "SMC", "PID", "mine") for suffix in ("csv", "json"))


def test_the_scorecard_refuses_a_file_that_is_not_an_autopilot(tmp_path, capsys):
    junk = tmp_path / "junk.fmu"
    junk.write_text("no")
    assert cli.main([str(junk), "--out", str(tmp_path / "score")]) == 2
    assert re.search(r"junk\.fmu is not an FMU", capsys.readouterr().err)
    assert not (tmp_path / "score").exists()


def test_an_autopilot_that_fails_is_scored_as_failed_and_the_rest_goes_on(tmp_path, capsys):
    from fmubuild.packaging import build_script
    from fmubuild.project import ROOT

    failing = build_script(ROOT / "tests" / "faulty" / "idle_pilot_slave.py", ("fmukit",),
                           tmp_path / "idle_pilot.fmu")
    out = tmp_path / "score"
    assert cli.main([str(failing), "--set", "autopilot.fail_time=150", "--seeds", "1",
                     "--workers", "1", "--out", str(out), "--backend", "inprocess"]) == 0
    err = capsys.readouterr().err
    assert ("note: controller 'idle_pilot': autopilot (idle_pilot.fmu) runs through FMI, not "
            "in-process: its module idle_pilot_slave is not importable here") in err
    assert err.count("note:") == 1
    text = (out / "scorecard.md").read_text()
    assert _rows(text, "## The paper's route")["idle_pilot"][:6] == ["failed"] * 6
    assert _rows(text, "## A 40 deg course change")["idle_pilot"] == ["failed"] * 4
    assert _rows(text, "## Wave ensemble")["idle_pilot"][-1] == "0/1"
    assert "- idle_pilot, calm water: `FMU 'autopilot': doStep at t = 150 s returned " \
           "fatal`" in text
    calm_pd = cost(simulate("calm_pd", backend="inprocess")).J      # the others still run
    assert _rows(text, "## The paper's route")["PD"][2] == f"{calm_pd:.1f}"


def test_a_scorecard_left_without_workers_says_so_and_exits_3(fmu_paths, tmp_path, capsys,
                                                              monkeypatch):
    from cosim.studies.sweep import NoWorkers

    def no_workers(*args, **kwargs):
        raise NoWorkers("no worker in the cluster for 60 s (none has joined since 12:00:00)")
    monkeypatch.setattr(cli, "score", no_workers)
    assert cli.main([str(fmu_paths["pd_autopilot"]), "--out", str(tmp_path / "s")]) == 3
    assert "no worker in the cluster for 60 s (none has joined since 12:00:00): no " \
           "scorecard written" in capsys.readouterr().err
