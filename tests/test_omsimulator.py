"""OMSimulator runs our SSP packages unchanged, and every parameter a scenario sets reaches the
FMU there: the guidance's route in its numeric form, since OMSimulator applies no String.

The quick suite (without ``pytest --long``) runs each scenario through one of OMSimulator's
interfaces, command line and API in turn: every scenario once, every interface at least
once."""
from __future__ import annotations

import os

import zipfile
from pathlib import Path

import numpy as np
import pytest

from autopilot_fmu.guidance import PAPER_ROUTE, numeric_route, route
from cosim import export as export_cli
from cosim import scenarios
from cosim.core.master import Master
from cosim.core.ssd import write_ssd
from cosim.interop.hosts import EngineError
from cosim.interop.hosts import run_omsimulator as run
from cosim.interop.ssp import SSD_NAME, described, export

ROOT = Path(__file__).resolve().parent.parent
OMS = Path(os.environ.get("OMSIMULATOR_HOME") or ROOT.parent / "shared" / "tools" / "omsimulator")
"""The prebuilt OMSimulator: $OMSIMULATOR_HOME, else ../shared/tools/omsimulator."""
needs_oms = pytest.mark.skipif(not (OMS / "bin" / "OMSimulator").is_file(),
                               reason=f"OMSimulator is not at {OMS} (../shared/tools/"
                                      "omsimulator, or set OMSIMULATOR_HOME; CI has it)")
SOUTH = "0,0;30,0;60,-25;90,-25"          # the paper's route mirrored: ends south of the start


def _gauss_seidel(name: str, overrides: dict | None = None):
    with Master(scenarios.load(name), overrides=overrides) as master:
        return master.run()


@pytest.fixture(scope="module")
def packages(fmu_paths, tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("ssp")
    (out / "south").mkdir()
    south = export("calm_pd", out / "south", {"guidance": {"waypoints": SOUTH}})
    return {**{name: export(name, out) for name in ("calm_pd", "waves_pd", "turning_circle")},
            "south": south}


def _same_to_12_digits(trace: dict, recording) -> int:
    """Every column both have, every row: OMSimulator's CSV holds 12 significant digits,
    so ours is rounded to them (%.12g) and must then be equal. The columns compared."""
    assert len(trace["time"]) == len(recording.t) == recording.rows
    common = [c for c in recording.columns if c in trace]
    for column in ["time", *common]:
        ours = recording.t if column == "time" else recording[column]
        rounded = np.array([float(f"{v:.12g}") for v in ours])
        assert np.array_equal(trace[column], rounded), column
    return len(common)


@needs_oms
@pytest.mark.parametrize("name, interface", [
    pytest.param(name, interface, marks=() if j == i % 2 else pytest.mark.long)
    for i, name in enumerate(["calm_pd", "waves_pd", "turning_circle"])
    for j, interface in enumerate(["cli", "api"])])
def test_omsimulator_runs_the_package_as_our_gauss_seidel_master_to_12_digits(
        packages, name, interface):
    """turning_circle ends at 300 s, where OMSimulator's float time makes a last step of
    2.8e-13 s: none on the FMUs' time base (it used to be refused, and OMSimulator aborted)."""
    recording = _gauss_seidel(name)
    compared = _same_to_12_digits(run(packages[name], OMS, interface, timeout=300), recording)
    assert compared == len(recording.columns)   # every signal, inputs and outputs


@needs_oms
def test_a_route_other_than_the_default_reaches_the_guidance_in_omsimulator(packages):
    """As a String it would be dropped and the ship would follow the paper's route north."""
    trace = run(packages["south"], OMS, "cli", timeout=300)
    _same_to_12_digits(trace, _gauss_seidel("calm_pd", {"guidance": {"waypoints": SOUTH}}))
    assert trace["ship.y"][-1] < -24.0


def test_the_package_gives_the_route_as_numbers_only(packages):
    guidance = described(packages["south"])[0].components["guidance"].parameters
    assert "waypoints" not in guidance
    assert guidance["n_waypoints"] == 4 and (guidance["wp2_x"], guidance["wp2_y"]) == (60.0, -25.0)
    assert route(guidance) == route({"waypoints": SOUTH})
    with zipfile.ZipFile(packages["south"]) as package:
        ssd = package.read(SSD_NAME).decode()
    assert "ssv:String" not in ssd
    assert '<oms:FixedStepMaster description="oms-ma" stepSize="0.1" />' in ssd


def test_the_numeric_route_runs_the_same_bits_as_the_string(fmu_paths):
    string = _gauss_seidel("calm_pd", {"guidance": {"waypoints": SOUTH}})
    numbers = _gauss_seidel("calm_pd", {"guidance": numeric_route(SOUTH)})
    assert np.array_equal(string.data, numbers.data) and string.error is None


@pytest.mark.parametrize("given, fragment", [
    ({"n_waypoints": 2, "wp1_x": 5.0, "waypoints": "0,0;6,0"}, "two different routes"),
    ({"wp1_x": 5.0}, "takes the route from the String waypoints"),
    ({**numeric_route("0,0;10,0"), "wp2_y": 3.0}, "uses only wp0 .. wp1"),
    ({"n_waypoints": 1}, "a route needs 2 to 16 points"),
])
def test_the_guidance_fmu_refuses_a_route_given_twice_or_half(fmu_paths, given, fragment):
    assert fragment in _gauss_seidel("calm_pd", {"guidance": given}).error


def test_both_forms_given_alike_or_the_string_at_its_default_are_one_route():
    assert route({**numeric_route(SOUTH), "waypoints": SOUTH}) == route({"waypoints": SOUTH})
    assert route({**numeric_route(SOUTH), "waypoints": PAPER_ROUTE}) == route(
        {"waypoints": SOUTH})


def test_a_string_omsimulator_would_drop_is_refused_and_export_warns(fmu_paths, tmp_path,
                                                                    capsys):
    system = scenarios.load("calm_smc")
    system.components["autopilot"].parameters["design_model"] = "ship"
    ssd = tmp_path / "ship_design.ssd"
    write_ssd(system, ssd, {c: str(system.fmu_path(c)) for c in system.components})
    assert export_cli.main([str(ssd), "--out", str(tmp_path)]) == 0
    assert ("warning: ship_design.ssp sets the String autopilot.design_model = 'ship'; "
            "OMSimulator and fmpy's SSP runner apply no String binding and would run with "
            "its default 'paper'") in capsys.readouterr().err
    with pytest.raises(EngineError, match="autopilot.design_model = 'paper', not 'ship'"):
        run(tmp_path / "ship_design.ssp", OMS)
