"""Values are checked against the FMU's declaration before any FMU call, identically on every
backend, and set exactly as given or refused by name (issue 25)."""
from __future__ import annotations

import json
import math
import subprocess
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from cosim import scenarios
from cosim.api import overrides_of, parse_setting
from cosim.core import master as master_module
from cosim.core.fmi import FmuInstance, read_description
from cosim.core.instance import FmuCallError
from cosim.core.master import BACKENDS, Master
from cosim.core.values import Declaration, checked, declarations, fmi_value, setting
from cosim import run as run_command
from helpers import command, fmu_variant

ROOT = Path(__file__).resolve().parent.parent
SEED = Declaration("wave_seed", "Integer", min=0, max=2**31 - 1)
HS = Declaration("Hs", "Real", min=0.0, max=0.1)
FREE = Declaration("Kp", "Real")
FLAG = Declaration("flag", "Boolean")
TEXT = Declaration("waypoints", "String")
MODE = Declaration("mode", "Enumeration", min=1, max=3, items=(("slow", 1), ("fast", 3)))
UNBOUNDED = Declaration("limit", "Real", max=math.inf)


@pytest.mark.parametrize("declaration, value, expected", [
    (SEED, 7, 7), (SEED, "7", 7), (SEED, "+7", 7), (SEED, " 7 ", 7), (SEED, 7.0, 7),
    (SEED, "7.0", 7), (SEED, "1e3", 1000), (SEED, np.int64(7), 7), (SEED, -0.0, 0),
    (SEED, 2**31 - 1, 2**31 - 1),
    (HS, "0.01", 0.01), (HS, "1e-2", 0.01), (HS, 0, 0.0), (HS, -0.0, -0.0),
    (HS, np.float32(0.0625), 0.0625), (HS, Fraction(1, 16), 0.0625),
    (FREE, "-1e300", -1e300), (FREE, ".5", 0.5),
    (UNBOUNDED, "inf", math.inf), (UNBOUNDED, math.inf, math.inf),
    (FLAG, "false", False), (FLAG, "FALSE", False), (FLAG, " True ", True), (FLAG, "1", True),
    (FLAG, "0", False), (FLAG, 0, False), (FLAG, 1, True), (FLAG, True, True),
    (TEXT, " 0,0; 1,1 ", " 0,0; 1,1 "), (TEXT, "", ""),
    (TEXT, "Øresund ≈ 1 km", "Øresund ≈ 1 km"),
    (MODE, "fast", 3), (MODE, 1, 1), (MODE, "3", 3),
])
def test_a_value_is_set_exactly_as_given(declaration, value, expected):
    result = checked("c", declaration, value)
    assert result == expected and type(result) is type(expected)
    if isinstance(expected, float):
        assert math.copysign(1, result) == math.copysign(1, expected)     # -0.0 stays -0.0


@pytest.mark.parametrize("declaration, value, fragment", [
    (SEED, 4294967297, "c.wave_seed = 4294967297 is outside the range of an FMI Integer "
                       "(32 bits); c.wave_seed is an Integer, a whole number from 0 to "
                       "2147483647"),
    (SEED, "4294967297", "c.wave_seed = '4294967297' is outside the range"),
    (SEED, 2**31, "is outside the range of an FMI Integer"),
    (SEED, -1, "c.wave_seed = -1 is outside its declared range"),
    (SEED, 1.5, "c.wave_seed = 1.5 is not a whole number"),
    (SEED, "1.5", "'1.5' is not a whole number"),
    (SEED, 1e30, "c.wave_seed = 1e+30 is outside the range of an FMI Integer"),
    (SEED, "1e30", "is outside the range of an FMI Integer"),
    (SEED, "1e999999999", "is outside the range of an FMI Integer"),   # no billion-digit int
    (SEED, math.nan, "is not a whole number"), (SEED, math.inf, "is not a whole number"),
    (SEED, True, "c.wave_seed = True is not a whole number"),
    (SEED, "0x10", "is not a whole number"), (SEED, "1_000", "is not a whole number"),
    (SEED, "", "c.wave_seed = '' is not a whole number"), (SEED, "١٢", "is not a whole number"),
    (SEED, None, "c.wave_seed = None is not a whole number"),
    (HS, math.nan, "c.Hs = nan is not a number (NaN); c.Hs is a finite Real, from 0.0 to 0.1"),
    (HS, "nan", "c.Hs = 'nan' is not a number (NaN)"),
    (HS, math.inf, "c.Hs = inf is not finite"), (HS, "-inf", "'-inf' is not finite"),
    (HS, 0.2, "c.Hs = 0.2 is outside its declared range; c.Hs is a finite Real, from 0.0 "
              "to 0.1"),
    (HS, "1e999", "is beyond the range of a double"),
    (HS, "1e-400", "is below the smallest double (it would be set as 0)"),
    (HS, 10**400, "is beyond the range of a double"),
    (HS, 2**53 + 1, "has no exact double (the nearest is 9007199254740992.0)"),
    (HS, Fraction(1, 3), "has no exact double"),
    (HS, "0x10", "is not a number"), (HS, "1_000", "is not a number"), (HS, "", "not a number"),
    (HS, " ", "not a number"), (HS, "½", "is not a number"), (HS, True, "is not a number"),
    (HS, [0.01], "is not a number"),
    (FREE, math.inf, "c.Kp = inf is not finite; c.Kp is a finite Real"),
    (UNBOUNDED, -math.inf, "is not finite; c.limit is a Real, not NaN"),
    (UNBOUNDED, math.nan, "is not a number (NaN)"),
    (FLAG, "yes", "c.flag = 'yes' is not a Boolean; c.flag is a Boolean: true, false, 1 or 0"),
    (FLAG, "fals", "'fals' is not a Boolean"), (FLAG, 2, "c.flag = 2 is not a Boolean"),
    (FLAG, 1.0, "is not a Boolean"), (FLAG, "", "is not a Boolean"),
    (TEXT, 7, "c.waypoints = 7 is not text"),
    (TEXT, "a\0b", "holds a NUL character, where an FMI string ends"),
    (TEXT, "\ud800", "is not encodable as UTF-8"),
    (MODE, 2, "c.mode = 2 is not one of its items; c.mode is an Enumeration item: 1 (slow), "
              "3 (fast)"),
    (MODE, "medium", "is not a whole number"), (MODE, 4, "is outside its declared range"),
])
def test_a_value_the_variable_cannot_take_is_refused_by_name(declaration, value, fragment):
    with pytest.raises(ValueError) as refused:
        checked("c", declaration, value)
    assert fragment in str(refused.value), str(refused.value)


def test_what_the_fmi_call_carries_is_the_type_alone():
    """``fmi_value`` (what Instance.set and the .ssd reader use) keeps what a C double
    holds, NaN and inf included, for the FMU to judge; it refuses what the call would
    change."""
    assert math.isnan(fmi_value("c.x", "Real", math.nan))
    assert fmi_value("c.x", "Real", "-inf") == -math.inf
    assert fmi_value("c.n", "Integer", "-2147483648") == -2**31
    for type_name, value in (("Integer", 2**32 + 1), ("Integer", 1.5), ("String", "a\0")):
        with pytest.raises(ValueError, match="c.x = "):
            fmi_value("c.x", type_name, value)
    with pytest.raises(ValueError, match="'Binary', which FMI 2.0 does not have"):
        fmi_value("c.x", "Binary", b"")


def test_only_what_a_master_may_set_in_initialisation_is_settable(fmu_paths):
    path = fmu_paths["ship"]
    declared = declarations(read_description(path, "ship"))
    assert declared["wave_seed"] == Declaration("wave_seed", "Integer", "parameter", "fixed",
                                                "exact", 0, 2**31 - 1)
    assert setting("ship", path, declared, "wave_seed", "7") == 7
    assert setting("ship", path, declared, "n1", "8.13") == 8.13          # an input
    with pytest.raises(ValueError) as output:
        setting("ship", path, declared, "x", 1.0)
    assert str(output.value).startswith("ship.x cannot be set: it is an output (initial "
                                        "calculated); FMU 'ship' (ship.fmu) takes values "
                                        "for delta_c, n1, n2, n3, x0,")
    with pytest.raises(ValueError, match="FMU 'ship' \\(ship.fmu\\) has no variable 'Hz'; "
                                         "it has: delta_c, n1"):
        setting("ship", path, declared, "Hz", 0.01)
    odd = {"k": Declaration("k", "Real", "calculatedParameter", "fixed", "calculated"),
           "c": Declaration("c", "Real", "output", "constant", "exact")}
    with pytest.raises(ValueError, match="c.k cannot be set: it is a calculatedParameter "
                                         "\\(initial calculated\\); FMU 'c' \\(f.fmu\\) "
                                         "takes values for no variable"):
        setting("c", "f.fmu", odd, "k", 1.0)
    with pytest.raises(ValueError, match="c.c cannot be set: it is a constant output"):
        setting("c", "f.fmu", odd, "c", 1.0)


def test_a_malformed_bound_in_a_model_description_names_the_file(fmu_paths, tmp_path):
    bad = fmu_variant(fmu_paths["ship"], tmp_path / "ship.fmu",
                      xml=lambda t: t.replace('min="0" max="2147483647"', 'min="zero"'))
    system = scenarios.load("waves_pd")
    system.components["ship"].source = str(bad)
    with pytest.raises(ValueError) as refused:
        Master(system)
    assert f"{bad} is not a readable FMU" in str(refused.value)
    assert "attribute 'min': 'zero'" in str(refused.value)


class _NoFmuCall:
    """A backend that fails the test if the master instantiates anything."""

    def __init__(self, path, name):
        pytest.fail(f"the master instantiated {name} before refusing the value")


@pytest.mark.parametrize("overrides, fragment", [
    ({"ship": {"wave_seed": 4294967297}}, "ship.wave_seed = 4294967297 is outside the range"),
    ({"ship": {"wave_seed": "4294967297"}}, "ship.wave_seed = '4294967297' is outside"),
    ({"ship": {"wave_seed": 1.5}}, "ship.wave_seed = 1.5 is not a whole number"),
    ({"ship": {"wave_seed": 1e30}}, "ship.wave_seed = 1e+30 is outside the range"),
    ({"ship": {"Hs": -1.0}}, "ship.Hs = -1.0 is outside its declared range; ship.Hs is a "
                             "finite Real, from 0.0 to 0.1"),
    ({"ship": {"Hs": math.nan}}, "ship.Hs = nan is not a number (NaN)"),
    ({"ship": {"n1": "100"}}, "ship.n1 = '100' is outside its declared range"),   # an input
    ({"autopilot": {"Kp": "1e9"}}, "autopilot.Kp = '1e9' is outside its declared range"),
    ({"guidance": {"waypoints": 5}}, "guidance.waypoints = 5 is not text"),
    ({"ship": {"x": 1.0}}, "ship.x cannot be set: it is an output"),
    ({"ship": {"Hz": 0.01}}, "FMU 'ship' (ship.fmu) has no variable 'Hz'; it has: "),
    ({"autopilot": {"psi": 0.5}}, "autopilot.psi is an input that the connection from "
                                  "ship.psi sets"),
    ({"boat": {"Hs": 0.01}}, "names the component 'boat'"),
    ({"ship": 0.01}, "set: the values for 'ship' must map variable names to values, got 0.01"),
    ([("ship", {"Hs": 0.01})], "set: overrides must map component names to their values"),
])
def test_both_backends_refuse_a_value_alike_before_any_fmu_call(fmu_paths, monkeypatch,
                                                                overrides, fragment):
    messages = set()
    for backend in BACKENDS:
        monkeypatch.setitem(master_module.BACKENDS, backend, _NoFmuCall)
        with pytest.raises(ValueError) as refused:
            Master(scenarios.load("waves_pd"), backend=backend, overrides=overrides)
        messages.add(str(refused.value))
    assert len(messages) == 1 and fragment in messages.pop()


def test_a_bad_binding_in_the_ssd_is_refused_naming_the_file(fmu_paths):
    system = scenarios.load("waves_pd")
    system.components["ship"].parameters["wave_components"] = 0
    with pytest.raises(ValueError) as refused:
        Master(system)
    assert str(refused.value) == (f"{system.path}: parameter binding ship.wave_components = 0 "
                                  "is outside its declared range; ship.wave_components is an "
                                  "Integer, a whole number from 1 to 5000")


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_master_keeps_the_values_as_set(fmu_paths, backend):
    overrides = {"ship": {"wave_seed": "7.0", "Hs": "1e-2", "T0": 1}}
    with Master(scenarios.load("waves_pd"), backend=backend, overrides=overrides) as master:
        assert master.overrides == {"ship": {"wave_seed": 7, "Hs": 0.01, "T0": 1.0}}
        assert type(master.parameters["ship"]["wave_seed"]) is int
        assert master.parameters["ship"]["n1"] == 8.13            # the .ssd's binding
        with pytest.raises(ValueError, match="ship.wave_seed = -3 is outside"):
            master.configure({"ship": {"wave_seed": -3}})
        assert master.overrides["ship"]["wave_seed"] == 7        # left as it was
        recording = master.run(1.0)
    assert recording.error is None
    assert recording.meta["parameters"]["ship"]["wave_seed"] == 7
    assert recording.meta["overrides"] == {"ship": {"wave_seed": 7, "Hs": 0.01, "T0": 1.0}}


@pytest.fixture
def flag_pilot(fmu_paths, tmp_path) -> Path:
    """The PD autopilot with a Boolean parameter ``flag`` declared (our FMUs have none)."""
    flag = ('<ScalarVariable name="flag" valueReference="99" causality="parameter" '
            'variability="fixed"><Boolean start="true"/></ScalarVariable>\n')
    return fmu_variant(fmu_paths["pd_autopilot"], tmp_path / "flag_pilot.fmu",
                       xml=lambda t: t.replace("</ModelVariables>", flag + "</ModelVariables>"))


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_boolean_reads_false_as_false(flag_pilot, backend):
    system = scenarios.load("calm_pd", flag_pilot)
    for text, value in (("false", False), ("False", False), ("0", False), ("TRUE", True)):
        with Master(system, backend=backend, overrides={"autopilot": {"flag": text}}) as master:
            assert master.parameters["autopilot"]["flag"] is value
    with pytest.raises(ValueError, match="autopilot.flag = 'fals' is not a Boolean"):
        Master(system, backend=backend, overrides={"autopilot": {"flag": "fals"}})


def test_an_instance_refuses_what_its_fmi_call_would_change(fmu_paths):
    """Set directly (no master), a value the FMI call cannot carry is refused, not wrapped
    or truncated; a value the FMU can judge reaches it."""
    ship = FmuInstance(fmu_paths["ship"], "ship")
    try:
        ship.enter_initialization()
        for value in (2**32 + 1, 1.5, "seven"):
            with pytest.raises(ValueError, match="ship.wave_seed = "):
                ship.set({"wave_seed": value})
        ship.set({"Hs": math.nan})                     # the FMU's own check refuses it
        with pytest.raises(FmuCallError, match="parameter Hs = nan is not finite"):
            ship.exit_initialization()
    finally:
        ship.free()


@pytest.mark.parametrize("text, expected", [
    ("ship.Hs=0.01", ("ship.Hs", "0.01")), ("ship.Hs=", ("ship.Hs", "")),
    ("guidance.waypoints=0,0;1=1", ("guidance.waypoints", "0,0;1=1")),
    ("ship.a.b=1", ("ship.a.b", "1")),
])
def test_a_setting_keeps_its_value_as_text(text, expected):
    assert parse_setting(text) == expected


@pytest.mark.parametrize("text", ["ship.Hs", "=1", "ship=1", ".Hs=1", "ship.=1", ""])
def test_a_setting_of_another_form_is_refused(text):
    with pytest.raises(ValueError, match="--set expects COMPONENT.VARIABLE=VALUE"):
        parse_setting(text)


def test_a_variable_set_twice_is_refused():
    assert overrides_of([("ship.Hs", "0.01"), ("autopilot.Kp", "2")]) == \
        {"ship": {"Hs": "0.01"}, "autopilot": {"Kp": "2"}}
    with pytest.raises(ValueError, match="set: ship.Hs is given twice \\('0.01' and '0.02'\\)"):
        overrides_of([("ship.Hs", "0.01"), ("ship.Hs", "0.02")])
    with pytest.raises(ValueError, match="set: 1 is not 'component.variable'"):
        overrides_of({1: 2})


def _cli(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    return command(run_command.main, *args, "--out", str(tmp_path / "out"), "--no-plot",
                   "--stop-time", "1")


@pytest.mark.parametrize("value, fragment", [
    ("4294967297", "ship.wave_seed = '4294967297' is outside the range of an FMI Integer"),
    ("1.5", "ship.wave_seed = '1.5' is not a whole number"),
    ("1e30", "ship.wave_seed = '1e30' is outside the range of an FMI Integer"),
])
def test_the_command_line_refuses_a_bad_value_alike_on_both_backends(fmu_paths, tmp_path,
                                                                     value, fragment):
    errors = set()
    for backend in BACKENDS:
        child = _cli(tmp_path, "waves_pd", "--set", f"ship.wave_seed={value}",
                     "--backend", backend)
        assert child.returncode == 2, child.stderr
        assert "Traceback" not in child.stderr and child.stderr.count("error:") == 1
        errors.add(child.stderr)
        assert not (tmp_path / "out").exists()          # nothing ran, nothing written
    assert len(errors) == 1 and fragment in errors.pop()


def test_the_command_line_refuses_a_boolean_it_cannot_read(flag_pilot, tmp_path):
    child = _cli(tmp_path, "calm_pd", "--autopilot", str(flag_pilot), "--set",
                 "autopilot.flag=fals")
    assert child.returncode == 2 and "Traceback" not in child.stderr
    assert child.stderr.strip() == ("error: autopilot.flag = 'fals' is not a Boolean; "
                                    "autopilot.flag is a Boolean: true, false, 1 or 0")


@pytest.mark.parametrize("setting", ["ship.Hs", "=0.01", "ship.=0.01"])
def test_the_command_line_refuses_a_setting_without_its_parts(tmp_path, setting):
    child = _cli(tmp_path, "calm_pd", "--set", setting)
    assert child.returncode == 2 and "Traceback" not in child.stderr
    assert child.stderr.count("error:") == 1 and "COMPONENT.VARIABLE=VALUE" in child.stderr


def test_the_metadata_records_the_value_set(fmu_paths, tmp_path):
    child = _cli(tmp_path, "waves_pd", "--set", "ship.wave_seed=7.0", "--set",
                 "ship.Hs=1e-2")
    assert child.returncode == 0, child.stderr
    meta = json.loads((tmp_path / "out" / "waves_pd.json").read_text())
    assert meta["overrides"] == {"ship": {"wave_seed": 7, "Hs": 0.01}}
    assert meta["settings"]["ship"]["wave_seed"] == meta["parameters"]["ship"]["wave_seed"] == 7


def test_a_value_with_a_unit_is_converted_and_said_and_a_wrong_unit_named():
    """Issue 38: '--set ship.psi0=40' was 40 rad without a word; '35deg' was 'not a number'."""
    from cosim.core.units import unit_notes
    from cosim.core.values import Declaration, checked

    psi0 = Declaration("psi0", "Real", unit="rad", min=-100.0, max=100.0)
    assert checked("ship", psi0, "40deg") == 40 * (math.pi / 180)
    assert checked("ship", psi0, " 40 deg ") == 40 * (math.pi / 180)
    assert checked("ship", psi0, "5e-1rad") == 0.5 and checked("ship", psi0, "1e1") == 10.0
    with pytest.raises(ValueError, match="ship.psi0 = '40kn' carries the unit 'kn'; it takes "
                                         "rad or deg"):
        checked("ship", psi0, "40kn")
    u0 = Declaration("u0", "Real", unit="m/s")
    assert checked("ship", u0, "1kn") == 1852 / 3600
    with pytest.raises(ValueError, match="carries the unit 'deg'; it takes no unit"):
        checked("pilot", Declaration("Kp", "Real"), "2deg")
    declared = {"ship": {"psi0": "rad", "u0": "m/s"}}
    assert unit_notes(declared, {"ship": {"psi0": "40deg", "u0": "0.3"}},
                      {"ship": {"psi0": 40 * (math.pi / 180), "u0": 0.3}}) == [
        f"ship.psi0 = 40deg is {40 * (math.pi / 180)!r} rad"]
    assert unit_notes(declared, {"ship": {"psi0": "40"}}, {"ship": {"psi0": 40.0}}) == [
        "ship.psi0 = 40.0 is taken in rad (2291.83 deg); for degrees write 40.0deg"]
