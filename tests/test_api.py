"""The Python entry point cosim.simulate, and the pytest plugin for your autopilot."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from cosim import SimulationError, simulate
from fmukit.packaging import ROOT, build_script

EXAMPLE = ROOT / "docs" / "own_autopilot" / "test_my_autopilot.py"


def test_simulate_returns_every_exchanged_signal_with_its_unit(fmu_paths):
    run = simulate("waves_pd", autopilot=fmu_paths["pid_autopilot"],
                   set={"ship.Hs": 0.004, "autopilot.Ki": 0.0}, stop_time=30)
    assert run.rows == 301 and run.t[-1] == 30.0
    assert run.units["ship.psi"] == "rad" and run.units["ship.r"] == "rad/s"
    assert run.units["autopilot.z"] == "rad.s" and run.units["guidance.wp_index"] == ""
    np.testing.assert_array_equal(run["autopilot.psi"], run["ship.psi"])      # exchanged
    np.testing.assert_array_equal(run["ship.delta_c"], run["autopilot.delta_c"])
    pd = simulate("waves_pd", set={"ship.Hs": 0.004}, stop_time=30)
    np.testing.assert_array_equal(run["ship.psi"], pd["ship.psi"])          # Ki = 0: a PD


def test_simulate_equals_the_command_line_run(fmu_paths, tmp_path):
    from cosim import run as cli

    assert cli.main(["calm_smc", "--out", str(tmp_path), "--no-plot"]) == 0
    csv = np.genfromtxt(tmp_path / "calm_smc.csv", delimiter=",", names=True)
    np.testing.assert_array_equal(simulate("calm_smc")["ship.psi"], csv["shippsi"])


@pytest.mark.parametrize("kwargs, error, fragment", [
    ({"set": {"ship.Hs": -1.0}}, SimulationError, "parameter Hs = -1.0 is outside its range"),
    ({"set": {"Hs": 0.01}}, ValueError, "set: 'Hs' is not 'component.variable'"),
    ({"set": {"boat.Hs": 0.01}}, ValueError, "names the component 'boat'"),
    ({"stop_time": 0.05}, ValueError, "not a whole number of 0.1 s steps"),
])
def test_simulate_refuses_bad_input_by_name(fmu_paths, kwargs, error, fragment):
    with pytest.raises(error, match=re.escape(fragment)):
        simulate("calm_pd", **kwargs)


@pytest.mark.parametrize("name, options", [
    ("pd_autopilot", []), ("pid_autopilot", []), ("pd_autopilot_c", []),
    # The SMC as printed turns slowly (eq 39, k2 = -2000; docs/reproduction.md): 25.7 deg
    # off course 60 s after the first turn. It is held to what it does, not to the PD's.
    ("smc_autopilot", ["--heading-bound", "30"]),
])
def test_the_example_test_file_passes_for_each_autopilot_of_the_project(
        fmu_paths, pytester, name, options):
    if name not in fmu_paths:
        pytest.skip("no C compiler on this machine (set CC or install gcc)")
    result = pytester.runpytest_subprocess(str(EXAMPLE), "--autopilot", str(fmu_paths[name]),
                                           *options, "-p", "no:cacheprovider")
    result.assert_outcomes(passed=8)


def test_the_example_test_file_fails_an_autopilot_that_does_not_steer(fmu_paths, pytester,
                                                                       tmp_path):
    idle = build_script(ROOT / "tests" / "faulty" / "idle_pilot_slave.py", ("fmukit",),
                        tmp_path / "idle_pilot.fmu")
    result = pytester.runpytest_subprocess(str(EXAMPLE), "--autopilot", str(idle),
                                           "-p", "no:cacheprovider")
    result.assert_outcomes(passed=6, failed=2)          # every check but the heading's
    result.stdout.fnmatch_lines(["*heading error * deg on the leg to waypoint 2 *allowed 5.00*"])


def test_the_plugin_checks_say_what_is_wrong_and_when(fmu_paths):
    from cosim.testing import check_rudder_rate, check_rudder_within_stops

    run = simulate("calm_pd", stop_time=120)
    with pytest.raises(AssertionError, match=r"rudder at 24\.\d\d deg at t = 9\d\.\d s, beyond"):
        check_rudder_within_stops(run, delta_max=math.radians(20))
    with pytest.raises(AssertionError, match=r"rudder moving at 20\.00 deg/s at t = .* faster"):
        check_rudder_rate(run, delta_rate_max=math.radians(10))
