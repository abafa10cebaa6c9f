"""PD, sliding-mode and guidance FMUs: conformance, equality with the modules, errors."""
from __future__ import annotations

import math

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from autopilot_fmu.design import PAPER_EQ45
from autopilot_fmu.guidance import WaypointGuidance
from autopilot_fmu.pd import PDAutopilot
from autopilot_fmu.smc import SlidingModeAutopilot, SlidingModeDesign
from cosim.core.instance import FmuCallError
from helpers import fmpy_cli, read_csv

NAMES = ["pd_autopilot", "smc_autopilot", "guidance"]
FEEDTHROUGH = {
    "pd_autopilot": {"delta_c": {"psi", "r", "psi_d"}},
    "smc_autopilot": {"delta_c": {"psi", "r", "psi_d"}, "psi_z": set(), "r_z": set(),
                      "sigma": {"psi", "r"}},
    "guidance": {"psi_d": {"x", "y"}, "wp_index": {"x", "y"}},
}
# Ramps, then steps of psi_d at 60 s and across +-180 deg at 90 s.
CONTROLLER_INPUT = ('"time","psi","r","psi_d"\n0,0.05,0,0\n30,0.2,0.01,0.7\n'
                    '60,0.6,0.004,0.7\n60,0.6,0.004,3.0\n90,3.1,-0.01,3.0\n'
                    '90,3.1,-0.01,-3.0\n120,-3.1,0,-3.0\n')


@pytest.mark.parametrize("name", NAMES)
def test_validates_with_a_unit_on_every_real_and_declared_feedthrough(fmu_paths, name):
    assert validate_fmu(str(fmu_paths[name])) == []
    md = read_model_description(str(fmu_paths[name]))
    defined = {u.name for u in md.unitDefinitions}
    for v in md.modelVariables:
        if v.type == "Real":
            assert v.unit in defined, v.name
    declared = {o.variable.name: {d.name for d in o.dependencies} for o in md.outputs}
    assert declared == FEEDTHROUGH[name]


def _simulate(fmu_paths, name, tmp_path, csv_text, outputs, stop):
    (tmp_path / "in.csv").write_text(csv_text)
    fmpy_cli("simulate", str(fmu_paths[name]), "--stop-time", str(stop), "--output-interval",
             "0.1", "--input-file",
             "in.csv", "--output-variables", *outputs, "--output-file", "out.csv",
             cwd=tmp_path)
    return read_csv(tmp_path / "out.csv")


def test_pd_fmu_under_fmpy_simulate_equals_the_module(fmu_paths, tmp_path):
    rows = _simulate(fmu_paths, "pd_autopilot", tmp_path, CONTROLLER_INPUT,
                     ["psi", "r", "psi_d", "delta_c"], 120)
    pd = PDAutopilot()
    assert len(rows) > 1000
    for row in rows:       # each row: the inputs the FMU holds and the output it gave
        assert row["delta_c"] == pytest.approx(pd.command(row["psi"], row["r"], row["psi_d"]),
                                               abs=1e-12)


def test_smc_fmu_under_fmpy_simulate_equals_the_module(fmu_paths, tmp_path):
    outputs = ["psi", "r", "psi_d", "delta_c", "psi_z", "r_z", "sigma"]
    rows = _simulate(fmu_paths, "smc_autopilot", tmp_path, CONTROLLER_INPUT, outputs, 120)
    smc = SlidingModeAutopilot(SlidingModeDesign.from_model(PAPER_EQ45),
                               psi_z=rows[0]["psi"], r_z=rows[0]["r"])
    for before, row in zip(rows, rows[1:]):
        smc.step(before["time"], row["time"] - before["time"], row["psi_d"])
        expected = {"delta_c": smc.command(row["psi"], row["r"], row["psi_d"]),
                    "psi_z": smc.psi_z, "r_z": smc.r_z, "sigma": smc.sigma(row["psi"], row["r"])}
        assert {k: row[k] for k in expected} == pytest.approx(expected, abs=1e-12)
    assert 3.0 < rows[-1]["psi_z"] < 3.4          # the short way from 3.0 to -3.0 (+3.28)


def test_guidance_fmu_under_fmpy_simulate_equals_the_module(fmu_paths, tmp_path):
    path = '"time","x","y"\n0,0,0\n100,30.2,0.3\n200,61,24\n300,95,25\n400,150,-10\n'
    rows = _simulate(fmu_paths, "guidance", tmp_path, path, ["x", "y", "psi_d", "wp_index"],
                     400)
    guidance = WaypointGuidance()
    for row in rows[1:]:
        guidance.update(row["x"], row["y"])
        assert row["psi_d"] == guidance.psi_d(row["x"], row["y"])
        assert row["wp_index"] == guidance.wp_index(row["x"], row["y"])
    assert [rows[i]["wp_index"] for i in (0, 1001, 2001, 3001)] == [1, 2, 3, 4]


@pytest.mark.parametrize("name, inputs", [
    ("pd_autopilot", ["psi", "r", "psi_d"]), ("smc_autopilot", ["psi", "r", "psi_d"]),
    ("guidance", ["x", "y"]),
])
@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_non_finite_input_fails_the_step_by_name(open_fmu, name, inputs, bad):
    for variable in inputs:
        fmu = open_fmu(name, f"{name}_{variable}")
        fmu.initialize()
        fmu.do_step(0.0, 0.1)
        fmu.set({variable: bad})
        with pytest.raises(FmuCallError) as refused:
            fmu.do_step(0.1, 0.1)
        assert refused.value.status == "fatal"
        assert any(f"input {variable}" in m for m in refused.value.messages)


@pytest.mark.parametrize("name, parameter, value, fragment", [
    ("guidance", "waypoints", "5,5", "at least two"),
    ("guidance", "waypoints", "0,0;x,3", "point 1"),
    ("guidance", "waypoints", "0,0;10,0;10,0", "consecutive"),
    ("guidance", "R_accept", 0.0, "> 0"),
    ("smc_autopilot", "omega_n", 0.0, "> 0"),
    ("smc_autopilot", "zeta", -0.1, "outside its range [0, 10]"),
    ("smc_autopilot", "phi_h", 0.0, "> 0"),
    ("smc_autopilot", "design_model", "eq46", "'paper'"),
    ("smc_autopilot", "lambda1", 0.5, "outside its range [-1000, 0]"),
    ("pd_autopilot", "Kp", math.inf, "not finite"),
])
def test_bad_parameters_are_reported_at_initialisation_by_name(open_fmu, name, parameter,
                                                               value, fragment):
    fmu = open_fmu(name)
    with pytest.raises(FmuCallError) as refused:
        fmu.initialize({parameter: value})
    assert refused.value.call == "exitInitializationMode"
    assert any(f"parameter {parameter}" in m and fragment in m for m in refused.value.messages)


def test_smc_design_model_ship_runs(open_fmu):
    fmu = open_fmu("smc_autopilot")
    fmu.initialize({"design_model": "ship", "u0": 0.3})
    fmu.set({"psi_d": 0.5})
    fmu.do_step(0.0, 0.1)
    assert fmu.get(["delta_c"])["delta_c"] < 0.0
