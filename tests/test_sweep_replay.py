"""A sweep's rows replay exactly and are not run twice: the settings that change nothing in
calm water, the runs they let a sweep share, the cosim.run command of every row (run here,
to the row's J bit for bit), the units of the tables and the summary per setting."""
from __future__ import annotations

import csv
import json
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from cosim import scenarios
from cosim.analysis.metrics import LAMBDA, Cost, cost_terms
from cosim.analysis.seastate import model_scale
from cosim.core.master import Master
from cosim.studies import campaign, sweep_task
from cosim.studies.sweep_spec import Spec
from cosim.studies.sweep_spec import CALM_WATER_INERT
from cosim.studies.sweep_tables import METRICS, TIMES, summary, summary_table, write_tables

EXAMPLE = Path(__file__).resolve().parent.parent / "docs" / "sweeps" / "example.toml"
CHANGED = {"T0": 1.7, "psi_w": 0.6, "wave_seed": 77, "wave_components": 9}
"""Another value of each of CALM_WATER_INERT, valid in any sea."""


def spec_file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return path


def _recording(scenario: str, ship: dict, stop_time: float = 100.0) -> np.ndarray:
    master = Master(scenarios.load(scenario), backend="inprocess", overrides={"ship": ship})
    try:
        return master.run(stop_time).data.copy()
    finally:
        master.free()


# -- what calm water ignores ------------------------------------------------------------
@pytest.mark.parametrize("scenario", ["calm_pd", "waves_pd", "waves_smc"])
def test_in_calm_water_the_wave_settings_change_no_bit_of_a_run(fmu_paths, scenario):
    """Every column of every row, for each parameter that runs are shared over; the same
    change in waves does change the run (so the comparison can see one)."""
    assert set(CHANGED) == set(CALM_WATER_INERT)
    calm = _recording(scenario, {"Hs": 0.0})
    waves = _recording(scenario, {"Hs": 0.005})
    for name, value in CHANGED.items():
        assert _recording(scenario, {"Hs": 0.0, name: value}).tobytes() == calm.tobytes(), name
        assert _recording(scenario, {"Hs": 0.005, name: value}).tobytes() != waves.tobytes(), \
            name


def test_the_example_runs_calm_water_once_per_controller_and_says_so():
    spec = Spec.read(EXAMPLE)
    groups = spec.shared_runs()
    assert len(spec.runs()) == 18 and len(groups) == 18 - 2 * 2
    shared = [g for g in groups if len(g) > 1]
    assert [(g[0]["controller"], {r["sea_state"] for r in g}, [r["wave_seed"] for r in g])
            for g in shared] == [("pd", {0}, [1, 2, 3]), ("smc", {0}, [1, 2, 3])]
    assert spec.sharing_notes() == ["sea_state 0 is calm water (Hs = 0): the wave_seed axis "
                                    "does not apply there; 2 runs instead of 6"]


def test_runs_are_shared_over_every_wave_setting_in_calm_water_and_only_there(tmp_path):
    spec = Spec.read(spec_file(tmp_path, """
        [controllers]
        pd = "waves_pd"
        calm = "calm_pd"
        [axes]
        Hs = [0.0, 0.005]
        psi_w = [0.0, 3.0]
        "ship.wave_components" = [20, 50]
        "ship.delta_rate_max" = [0.2, 0.3]
    """))
    sizes = {}
    for group in spec.shared_runs():
        key = (group[0]["controller"], group[0]["Hs"])
        sizes.setdefault(key, []).append(len(group))
        assert len({(r["controller"], r["ship.delta_rate_max"]) for r in group}) == 1
    # Hs = 0: psi_w and wave_components do not matter; the rate limit does. In waves, all do.
    assert sizes == {("pd", 0.0): [4, 4], ("pd", 0.005): [1] * 8,
                     ("calm", 0.0): [4, 4], ("calm", 0.005): [1] * 8}
    assert spec.sharing_notes() == ["Hs 0.0 is calm water (Hs = 0): the psi_w and "
                                    "ship.wave_components axes do not apply there; 4 runs "
                                    "instead of 16"]
    own = Spec.read(spec_file(tmp_path, '[controllers]\ncalm = "calm_pd"\n'
                                              '[axes]\nwave_seed = [1, 2]\n'))
    assert own.sharing_notes() == ["controller 'calm' (calm_pd) is calm water (Hs = 0): the "
                                   "wave_seed axis does not apply there; 1 run instead of 2"]


# -- the command of each row ------------------------------------------------------------
REPLAYED = """
name = "replay"
stop_time = 30
[controllers]
pd = "waves_pd"
smc = { scenario = "waves_smc", set = { "autopilot.eta_h" = 7.3 } }
mine = { autopilot = "mine.fmu" }
[axes]
wave_seed = [4, 5]
sea_state = [0, 3]
route = ["0,0;30,0;60,25;90,25", "0,0;40,10"]
"ship.delta_rate_max" = [0.30000000000000004]
"""


def _settings_of(command: str) -> tuple[list[str], dict[str, str]]:
    words = shlex.split(command)
    sets = [words[i + 1] for i, word in enumerate(words) if word == "--set"]
    return words, dict(s.split("=", 1) for s in sets)


def test_a_row_s_command_gives_every_setting_exactly(fmu_paths, tmp_path):
    (tmp_path / "mine.fmu").write_bytes(fmu_paths["pid_autopilot"].read_bytes())
    spec = Spec.read(spec_file(tmp_path, REPLAYED))
    for run in spec.runs():
        words, sets = _settings_of(spec.replay(run))
        scenario, overrides = spec.settings(run)
        assert words[:4] == ["python", "-m", "cosim.run", scenario]
        assert words[words.index("--stop-time") + 1] == "30"
        expected = {f"{c}.{v}": value for c, values in overrides.items()
                    for v, value in values.items()}
        assert set(sets) == set(expected)
        for target, value in expected.items():          # read back as the master reads it
            assert type(value)(sets[target]) == value, (target, sets[target], value)
        assert ("--autopilot" in words) == (run["controller"] == "mine")
    Hs, T0 = model_scale(3)
    assert f"ship.T0={T0!r}" in spec.replay(next(r for r in spec.runs() if r["sea_state"] == 3))


@pytest.mark.timeout(600, method="thread")
def test_running_a_row_s_command_gives_its_J_bit_for_bit(fmu_paths, tmp_path, scheduler):
    """The sweep on Dask, then each kind of row's command in a child process: a wave run,
    a calm-water row that shares another seed's run, a controller with its own settings and
    a user's autopilot FMU."""
    (tmp_path / "mine.fmu").write_bytes(fmu_paths["pid_autopilot"].read_bytes())
    spec = Spec.read(spec_file(tmp_path, REPLAYED))
    out = tmp_path / "out"
    out.mkdir()
    rows = campaign.execute(spec, out, scheduler, progress=False)
    assert len(rows) == 24 and all(r["status"] == "ok" for r in rows), rows
    chosen = {(r["controller"], r["sea_state"], r["run_id"] != r["ran_as"]): r for r in rows
              if r["route"] == "0,0;40,10" and (r["wave_seed"] == 5 or r["controller"] == "pd")}
    for key in [("pd", 3, False), ("pd", 0, True), ("smc", 3, False), ("mine", 0, True)]:
        row = chosen[key]
        replayed = _replay(row["command"], tmp_path / "replay" / "-".join(map(str, key)))
        assert replayed == tuple(row[m] for m in ("psi_E", "sum_delta2", "J")), key
    journal = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines()]
    assert len(journal) == 24 - 6 and all(r["command"] == spec.replay(r) for r in journal)
    sweep_task.free_masters()


def _replay(command: str, out: Path) -> tuple[float, float, float]:
    """psi_E, sum delta^2 and J of eq (19) of the run ``command`` writes, from its CSV."""
    words = shlex.split(command)
    assert words[:3] == ["python", "-m", "cosim.run"]
    child = subprocess.run([sys.executable, *words[1:], "--out", str(out), "--no-plot"],
                           capture_output=True, text=True, timeout=240)
    assert child.returncode == 0, child.stderr
    (written,) = out.glob("*.csv")
    with open(written, newline="") as f:
        table = list(csv.reader(f))
    column = {name: np.array([float(line[i]) for line in table[1:]])
              for i, name in enumerate(table[0])}
    terms = cost_terms(column["guidance.psi_d"], column["ship.psi"], column["ship.delta"])
    J = Cost(*terms, LAMBDA).J
    return (*terms, J)


# -- the tables -------------------------------------------------------------------------
def _rows(spec: Spec) -> list[dict]:
    """Rows as a sweep's, each metric a distinct number, shared runs sharing them."""
    rows = []
    for g, group in enumerate(spec.shared_runs()):
        for run in group:
            rows.append({**run, "status": "ok", "error": "", "ran_as": group[0]["run_id"],
                         "command": spec.replay(run), "backend": "fmi",
                         **{m: 10.0 + 3 * g + len(m) for m in METRICS},
                         **{t: 0.5 for t in TIMES}})
    order = [r["run_id"] for r in spec.runs()]
    return sorted(rows, key=lambda r: order.index(r["run_id"]))


def test_every_column_with_a_unit_names_it(tmp_path):
    spec = Spec.read(spec_file(tmp_path, '[axes]\nwave_seed = [1, 2]\n'
                                               'Hs = [0.0, 0.01]\n"ship.delta_rate_max" = [0.3]\n'))
    written = write_tables(_rows(spec), tmp_path, csv=True, spec=spec)
    units = {**METRICS, **TIMES, "Hs": "m", "ship.delta_rate_max": "rad/s"}
    assert units["sim_seconds"] == "s"
    assert {p.name for p in written} == {"results.parquet", "results.json", "results.csv",
                                         "summary.csv"}
    with open(tmp_path / "results.csv", newline="") as f:
        header = next(csv.reader(f))
    said = json.loads((tmp_path / "results.json").read_text())["units"]
    table = pq.read_table(tmp_path / "results.parquet")
    for name in table.column_names:
        unit = units.get(name, "")
        assert (f"{name} [{unit}]" if unit else name) in header
        assert said[name] == unit
        assert table.schema.field(name).metadata == {b"unit": unit.encode()}


def test_the_summary_is_per_setting_and_counts_a_shared_run_once(tmp_path):
    spec = Spec.read(spec_file(tmp_path, '[axes]\nwave_seed = [1, 2, 3]\n'
                                               'sea_state = [0, 2]\n'))
    rows = _rows(spec)
    header, *lines = summary_table(spec, rows)
    assert header[:4] == ["sea_state", "controller", "runs ok", "runs failed"]
    assert "J median [rad^2]" in header and "J q25 [rad^2]" in header
    cells = {(line[0], line[1]): dict(zip(header, line)) for line in lines}
    assert set(cells) == {(s, c) for s in (0, 2) for c in ("pd", "smc")}
    for (sea_state, controller), cell in cells.items():
        J = np.array(sorted({r["ran_as"]: r["J"] for r in rows if r["controller"] == controller
                             and r["sea_state"] == sea_state}.values()))
        assert cell["runs ok"] == len(J) == (1 if sea_state == 0 else 3)
        assert cell["J median [rad^2]"] == np.median(J)
        assert cell["J q25 [rad^2]"] == np.percentile(J, 25)
        assert cell["J max [rad^2]"] == J.max()
    printed = summary(spec, rows).splitlines()
    assert printed[0] == "spec: 12 combinations in 8 runs (4 share an equivalent run's " \
                         "result), 8 ok, 0 failed"
    assert "median, IQR (interquartile range, 25th to 75th percentile)" in printed[1]
    J = cells[2, "smc"]
    assert any(line.split()[:3] == ["2", "smc", "3"] and f"{J['J median [rad^2]']:.2f}" in line
               for line in printed)
