"""What a new user reads when bringing an autopilot of their own: every message names the
input it refuses and says what was expected (issue 27).

Each test builds a small FMU of its own into the test's folder, as a user would, from a
script written here.
"""
from __future__ import annotations

import math
import os
import shutil
import sys
import textwrap
import warnings
from pathlib import Path

import pytest

from cosim import simulate
from cosim.api import SimulationError
from cosim.core.system import close_matches
from cosim.run import main as run_cli
from cosim.scenarios.autopilot import DESCRIPTIONS, PORTS, AutopilotError, check_autopilot
from fmubuild import cli
from fmubuild.packaging import build_script
from fmubuild.project import ROOT

FAILING_PILOT = '''\
"""A PD autopilot of a user's own that divides by zero once t reaches t_fail: in its step
(where = 0) or in its rudder command, an output (where = 1)."""
from fmukit.autopilot import INPUTS, rudder_command
from fmukit.slave import ModelSlave, Var


class Law:
    def __init__(self, t_fail: float, where: int):
        self.t_fail, self.where, self.t = t_fail, where, 0.0

    def do_step(self, t: float) -> None:
        self.t = t
        if self.where == 0 and t >= self.t_fail:
            print(1.0 / 0.0)

    def command(self, psi: float, psi_d: float) -> float:
        if self.where == 1 and self.t >= self.t_fail:
            return (psi - psi_d) / 0.0
        return 2.0 * (psi - psi_d)

    def snapshot(self) -> dict:
        return {"t": self.t}

    def restore(self, saved: dict) -> None:
        self.t = saved["t"]


class FailingPilot(ModelSlave):
    model_name = "failing_pilot"
    description = "a user's autopilot with a bug"
    variables = (*INPUTS,
                 rudder_command(("psi", "psi_d"), lambda s: s.model.command(s.psi, s.psi_d)),
                 Var.parameter("t_fail", 1.0, "s", "when it divides by zero", 0.0, 1e6),
                 Var.parameter("where", 0, "1", "0 in its step, 1 in its command", 0, 1))

    def build_model(self) -> Law:
        return Law(self.t_fail, self.where)

    def step_model(self, t: float, h: float) -> None:
        self.model.do_step(t)
'''


def _script(folder: Path, name: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    script = folder / name
    script.write_text(textwrap.dedent(text))
    return script


def _line_of(script: Path, text: str) -> int:
    """The number of the line of ``script`` that holds ``text``."""
    return next(i for i, line in enumerate(script.read_text().splitlines(), 1) if text in line)


@pytest.fixture(scope="module")
def failing_pilot(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("failing")
    return build_script(_script(folder, "failing_pilot.py", FAILING_PILOT), ("fmukit",), folder)


@pytest.mark.timeout(300)
@pytest.mark.parametrize("backend", ["fmi", "inprocess"])
@pytest.mark.parametrize("where, function, fault", [
    (0, "do_step", "1.0 / 0.0"),
    (1, "command", "(psi - psi_d) / 0.0"),        # in an output: it read NaN, unexplained
])
def test_an_exception_in_a_users_fmu_names_their_file_and_line(fmu_paths, failing_pilot,
                                                                tmp_path, monkeypatch, backend,
                                                                where, function, fault):
    script = failing_pilot.with_name("failing_pilot.py")
    # In-process imports the script from its folder. An FMI run in this process left the
    # module pythonfmu imported from the FMU's (removed) folder, and that FMU judged so.
    monkeypatch.syspath_prepend(str(script.parent))
    monkeypatch.delitem(sys.modules, "failing_pilot", raising=False)
    fmu = shutil.copy(failing_pilot, tmp_path / failing_pilot.name)
    with pytest.raises(SimulationError) as failed, warnings.catch_warnings():
        warnings.simplefilter("error")      # no note that the FMU runs through FMI after all
        simulate("calm_pd", autopilot=fmu, set={"autopilot.where": where}, stop_time=3.0,
                 backend=backend)
    message = str(failed.value)
    assert message.startswith("FMU 'autopilot': doStep at t = "), message
    assert (f"failing_pilot.py:{_line_of(script, fault)} in {function}: ZeroDivisionError: "
            "float division by zero" in message), message
    assert "Traceback" not in message and "slave.py" not in message


# -- python -m fmukit.build ---------------------------------------------------------------
LAW_PILOT = '''\
"""An autopilot whose law is in a module of the user's own, beside the script."""
from fmukit.autopilot import INPUTS, rudder_command
from fmukit.slave import ModelSlave, Var
from mylaw import pd


class Law:
    def snapshot(self) -> dict:
        return {}

    def restore(self, saved: dict) -> None:
        pass


class LawPilot(ModelSlave):
    model_name = "law_pilot"
    description = "a PD in a module of its own"
    variables = (*INPUTS, rudder_command(("psi", "r", "psi_d"),
                                         lambda s: pd(s.psi - s.psi_d, s.r)))

    def build_model(self) -> Law:
        return Law()

    def step_model(self, t: float, h: float) -> None:
        pass
'''


@pytest.fixture
def law_pilot(tmp_path) -> Path:
    """The script, its module mylaw.py beside it, not included."""
    _script(tmp_path / "mine", "mylaw.py", "def pd(e, r):\n    return 2.0 * e + 50.0 * r\n")
    return _script(tmp_path / "mine", "law_pilot.py", LAW_PILOT)


@pytest.mark.parametrize("where", ["script", "project", "elsewhere"])
def test_a_module_not_included_is_named_with_the_include_that_carries_it(
        law_pilot, tmp_path, monkeypatch, capsys, where):
    """From any working folder: the script's own (where the import would succeed), the
    project's, or one holding neither."""
    cwd = {"script": law_pilot.parent, "project": ROOT, "elsewhere": tmp_path}[where]
    monkeypatch.chdir(cwd)
    given, shown = (os.path.relpath(p) if cwd in p.parents else str(p)
                    for p in (law_pilot, law_pilot.with_name("mylaw.py")))
    assert cli.main([given]) == 1
    err = capsys.readouterr().err
    assert f"cannot build an FMU from {given}" in err
    assert f"imports mylaw (found at {shown})" in err
    assert f"python -m fmukit.build {given} --include {shown}\n" in err
    assert not list(law_pilot.parent.glob("*.fmu"))


@pytest.mark.timeout(300)
def test_the_command_the_message_gives_builds_the_fmu(law_pilot, monkeypatch, capsys):
    monkeypatch.chdir(law_pilot.parent)
    assert cli.main([law_pilot.name]) == 1
    command = capsys.readouterr().err.rstrip().splitlines()[-1].split()
    assert command[:3] == ["python", "-m", "fmukit.build"]
    assert cli.main(command[3:]) == 0
    assert (law_pilot.parent / "law_pilot.fmu").is_file()


def test_every_missing_module_is_named_at_once_and_an_optional_one_is_not(tmp_path,
                                                                           monkeypatch,
                                                                           capsys):
    _script(tmp_path, "gains.py", "KP = 2.0\n")
    script = _script(tmp_path, "several.py", '''\
        import gains
        import nowhere_to_be_found
        from fmukit.slave import ModelSlave
        try:
            import an_optional_speedup
        except ImportError:
            an_optional_speedup = None
        ''')
    monkeypatch.chdir(tmp_path)
    assert cli.main([script.name]) == 1
    err = capsys.readouterr().err
    assert "imports gains (found at gains.py)" in err
    assert "imports nowhere_to_be_found (found neither here nor among the packages" in err
    assert "--include gains.py --include PATH/TO/nowhere_to_be_found.py" in err
    assert "an_optional_speedup" not in err


def test_a_module_an_included_package_imports_is_named_by_its_importer(law_pilot, monkeypatch,
                                                                       capsys):
    """mylaw carried as a package of the user's, which needs a module left beside it."""
    folder = law_pilot.parent
    _script(folder / "mylaw", "__init__.py", "from mylaw.gains import pd\n")
    _script(folder / "mylaw", "gains.py", "import tuning\n\ndef pd(e, r):\n    return e\n")
    _script(folder, "tuning.py", "KP = 2.0\n")
    (folder / "mylaw.py").unlink()
    monkeypatch.chdir(folder)
    assert cli.main([law_pilot.name, "--include", "mylaw"]) == 1
    err = capsys.readouterr().err
    assert "  mylaw/gains.py imports tuning (found at tuning.py)\n" in err
    assert "python -m fmukit.build law_pilot.py --include mylaw --include tuning.py\n" in err


def test_an_include_that_does_not_exist_is_named(law_pilot, capsys):
    assert cli.main([str(law_pilot), "--include", str(law_pilot.with_name("mylaws.py"))]) == 1
    err = capsys.readouterr().err
    assert err == (f"error: {law_pilot.with_name('mylaws.py')}, to be carried by "
                   f"{law_pilot.name}'s FMU, does not exist\n")


def test_a_syntax_error_is_one_message_with_its_file_line_and_the_line(tmp_path, capsys):
    script = _script(tmp_path, "broken.py", FAILING_PILOT.replace(
        'return {"t": self.t}', 'return {"t": self.t)'))
    line = _line_of(script, '{"t": self.t)')
    assert cli.main([str(script)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"error: {script}:{line}: SyntaxError: ")
    assert '\n    return {"t": self.t)\n' in err
    assert "Traceback" not in err and not list(tmp_path.glob("*.fmu"))


def test_a_script_that_exits_when_imported_is_refused_by_its_line(tmp_path, capsys):
    script = _script(tmp_path, "exits.py", FAILING_PILOT + "\nimport sys\nsys.exit(0)\n")
    assert cli.main([str(script)]) == 1
    err = capsys.readouterr().err
    assert (f"cannot build an FMU from {script}: {script}:{_line_of(script, 'sys.exit(0)')} "
            "called sys.exit(0) when imported") in err
    assert not list(tmp_path.glob("*.fmu"))


# -- the port contract ------------------------------------------------------------------------
DEGREES_PILOT = '''\
"""An autopilot in degrees, with a yaw rate of another name and psi_d a parameter."""
from fmukit.slave import ModelSlave, Var


class Law:
    def snapshot(self) -> dict:
        return {}

    def restore(self, saved: dict) -> None:
        pass


class DegreesPilot(ModelSlave):
    model_name = "degrees_pilot"
    description = "ports in degrees"
    variables = (Var.input("psi", 0.0, "deg", "heading"),
                 Var.input("R", 0.0, "deg/s", "yaw rate"),
                 Var.parameter("psi_d", 0.0, "rad", "desired heading"),
                 Var.output("delta_c", "deg", "rudder", depends=("psi",), get=lambda s: -s.psi))

    def build_model(self) -> Law:
        return Law()

    def step_model(self, t: float, h: float) -> None:
        pass
'''


@pytest.fixture(scope="module")
def degrees_pilot(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("degrees")
    return build_script(_script(folder, "degrees_pilot.py", DEGREES_PILOT), ("fmukit",),
                        folder)


def _refusal(fmu: Path, port_map: dict[str, str] | None = None) -> str:
    with pytest.raises(AutopilotError) as refused:
        check_autopilot(fmu, port_map)
    return str(refused.value)


def test_every_broken_port_is_listed_at_once_with_what_was_expected(degrees_pilot):
    message = _refusal(degrees_pilot)
    one_degree = f"{math.pi / 180:.6g}"
    expected = [
        (f"port 'psi' is in deg: expected rad; the interfaces are in SI units, angles in "
         f"radians: declare psi in rad and convert inside the FMU (1 deg = {one_degree} rad)"),
        f"no port 'r': expected a Real input in rad/s ({DESCRIPTIONS['r']}); did you mean 'R'?",
        "port 'psi_d' is of causality parameter and type Real: expected a Real input in rad",
        "port 'delta_c' is in deg: expected rad;"]
    assert message.startswith(f"{degrees_pilot} does not keep the autopilot contract")
    listed = [line[4:] for line in message.splitlines() if line.startswith("  - ")]
    assert len(listed) == len(expected)
    for line, start in zip(listed, expected):
        assert line.startswith(start), (line, start)
    assert "It has inputs: psi (Real, deg), R (Real, deg/s)" in message


def test_a_mapped_port_in_degrees_per_second_is_named_by_both_names(degrees_pilot):
    message = _refusal(degrees_pilot, {"r": "R"})
    assert ("port 'R' (for r) is in deg/s: expected rad/s; the interfaces are in SI units, "
            f"angles in radians: declare R in rad/s and convert inside the FMU "
            f"(1 deg/s = {math.pi / 180:.6g} rad/s)") in message
    assert "no port" not in message


@pytest.mark.timeout(300)
def test_cosim_run_refuses_it_before_anything_runs(fmu_paths, degrees_pilot, tmp_path,
                                                   capsys):
    with pytest.raises(SystemExit) as refused:
        run_cli(["calm_pd", "--autopilot", str(degrees_pilot), "--out", str(tmp_path),
                 "--no-plot"])
    assert refused.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n  - ") == 4 and "Traceback" not in err
    assert not list(tmp_path.rglob("*.csv"))


def test_a_mapped_name_that_is_no_port_gets_the_closest_port(degrees_pilot):
    assert _refusal(degrees_pilot, {"ps": "psi"}).endswith(
        f"--map names 'ps', which is not a port of an autopilot ({', '.join(PORTS)}); "
        "did you mean 'psi'?")


# -- names looked up by a user's string -------------------------------------------------------
@pytest.mark.parametrize("names, typed, meant", [
    (["Hs", "h_max", "T0"], "hs", ["Hs"]),                      # case first
    (["Kp", "Kd", "kd", "delta_max"], "KD", ["Kd", "kd"]),     # every case variant, first
    (["guidance", "autopilot", "ship"], "shp", ["ship"]),
    (["delta_rate_max", "delta_max"], "delta_mx", ["delta_max", "delta_rate_max"]),  # best first
    (["Hs", "T0"], "wave_seed", []),                            # nothing close: no guess
])
def test_close_matches_put_a_difference_of_case_first(names, typed, meant):
    assert close_matches(typed, names) == meant
    assert typed not in close_matches(typed, [*names, typed])   # never the name itself


@pytest.mark.parametrize("setting, hint", [
    ("ship.hs", "FMU 'ship' (ship.fmu) has no variable 'hs'; it has: "),
    ("shp.Hs", "--set names the component 'shp'; the system has guidance, autopilot, ship"),
    ("ship.kd", "FMU 'ship' (ship.fmu) has no variable 'kd'; it has: "),
])
def test_an_unknown_name_in_set_gets_the_closest_names(fmu_paths, setting, hint):
    meant = {"ship.hs": "'Hs'", "shp.Hs": "'ship'", "ship.kd": "'autopilot.Kd'"}[setting]
    with pytest.raises(ValueError) as refused:
        simulate("calm_pd", set={setting: 1}, stop_time=1.0)
    message = str(refused.value)
    assert message.startswith(hint) and message.endswith(f"; did you mean {meant}?"), message


def test_a_name_like_none_gets_no_guess(fmu_paths, tmp_path, capsys):
    assert run_cli(["calm_pd", "--set", "ship.wave_height=1", "--out", str(tmp_path),
                    "--no-plot"]) == 2
    err = capsys.readouterr().err
    assert "has no variable 'wave_height'; it has: " in err and "did you mean" not in err
