"""Building FMUs: your own script with fmukit, the autopilot in C, and no compiler."""
from __future__ import annotations

import math
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from cosim import scenarios
from cosim.core.master import Master
from cosim.interop.hosts import run as run_engine
from cosim.interop.ssp import export
from fmubuild import cli
from fmubuild.project import ROOT


def _run(scenario: str, autopilot: Path | None = None, coupling: str = "gauss-seidel"):
    master = Master(scenarios.load(scenario, autopilot), coupling=coupling)
    try:
        recording = master.run()
    finally:
        master.free()
    assert recording.error is None
    return recording


def _start(fmu: Path, name: str) -> str:
    return next(v.start for v in read_model_description(str(fmu)).modelVariables
                if v.name == name)


def test_your_script_builds_into_a_valid_fmu_that_runs_as_autopilot(fmu_paths, tmp_path,
                                                                     capsys):
    script = tmp_path / "my_pid.py"
    script.write_text((ROOT / "autopilot_fmu" / "pid_autopilot_slave.py").read_text()
                      .replace('model_name = "pid_autopilot"', 'model_name = "my_pid"'))
    assert cli.main([str(script)]) == 0
    fmu = tmp_path / "my_pid.fmu"
    assert f"built and validated {fmu}" in capsys.readouterr().out
    assert validate_fmu(str(fmu)) == []
    mine, ours = _run("waves_pd", fmu), _run("waves_pid")
    np.testing.assert_array_equal(mine["ship.psi"], ours["ship.psi"])


def test_your_script_builds_as_fmi3_beside_it_and_runs_as_autopilot(tmp_path, capsys):
    script = tmp_path / "my_pid.py"
    script.write_text((ROOT / "autopilot_fmu" / "pid_autopilot_slave.py").read_text()
                      .replace('model_name = "pid_autopilot"', 'model_name = "my_pid"'))
    assert cli.main([str(script), "--fmi", "3"]) == 0
    fmu = tmp_path / "fmi3" / "my_pid.fmu"
    assert f"built and validated {fmu}" in capsys.readouterr().out
    assert validate_fmu(str(fmu)) == [] and read_model_description(str(fmu)).fmiVersion == "3.0"
    assert not (tmp_path / "my_pid.fmu").exists()
    mine, ours = _run("waves_pd", fmu), _run("waves_pid")
    np.testing.assert_array_equal(mine["ship.psi"], ours["ship.psi"])


def test_an_fmi_version_fmukit_does_not_build_is_refused_by_the_command(capsys):
    with pytest.raises(SystemExit):
        cli.main(["pd_autopilot", "--fmi", "1"])
    assert "--fmi: invalid choice: 1 (choose from 2, 3)" in capsys.readouterr().err


def test_your_scripts_fmu_names_fmukit_and_only_the_author_it_declares(tmp_path):
    script = tmp_path / "mine.py"
    script.write_text((ROOT / "autopilot_fmu" / "pid_autopilot_slave.py").read_text()
                      .replace('model_name = "pid_autopilot"',
                               'model_name = "mine"\n    author = "A. User"'))
    assert cli.main([str(script)]) == 0
    described = read_model_description(str(tmp_path / "mine.fmu"))
    assert described.generationTool.startswith("fmukit ")
    assert (described.author, described.version, described.license) == ("A. User", None, None)
    with zipfile.ZipFile(tmp_path / "mine.fmu") as fmu:
        assert {"documentation/index.html", "model.png"} <= set(fmu.namelist())


def test_scripts_built_one_after_another_carry_their_own_modules(tmp_path):
    """pythonfmu imports a script's modules from a temporary folder; the next build must
    not find them there (they would also shadow its own)."""
    pid = (ROOT / "autopilot_fmu" / "pid_autopilot_slave.py").read_text()
    for folder, ki in (("one", "0.1"), ("two", "0.2")):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "gains.py").write_text(f"KI = {ki}\n")
        (tmp_path / folder / f"{folder}.py").write_text(
            pid.replace('model_name = "pid_autopilot"', f'model_name = "{folder}"')
               .replace("Ki: float = 0.04", "Ki: float = gains.KI")
               .replace("import math\n", "import math\n\nimport gains\n", 1))
        assert cli.main([str(tmp_path / folder / f"{folder}.py"),
                         "--include", str(tmp_path / folder / "gains.py")]) == 0
    assert _start(tmp_path / "one" / "one.fmu", "Ki") == "0.1"
    assert _start(tmp_path / "two" / "two.fmu", "Ki") == "0.2"


def test_a_script_without_a_model_is_refused_by_name(tmp_path, capsys):
    script = tmp_path / "empty.py"
    script.write_text("x = 1\n")
    assert cli.main([str(script)]) == 1
    assert f"cannot build an FMU from {script}: ValueError: {script} defines no subclass of " \
           "fmukit.slave.ModelSlave (the FMU's model)" in capsys.readouterr().err


def test_the_c_autopilot_equals_the_python_pd(c_autopilot):
    assert validate_fmu(str(c_autopilot)) == []
    c, python = _run("waves_pd", c_autopilot), _run("waves_pd")
    assert np.abs(c["ship.psi"] - python["ship.psi"]).max() <= 1e-9
    assert len(c.t) == 4001


def test_the_c_autopilot_runs_in_libcosim_and_ecos_from_a_package(c_autopilot, tmp_path):
    package = export("waves_pd", tmp_path, autopilot=c_autopilot)
    python = _run("waves_pd", coupling="jacobi")
    for engine, first in (("libcosim", 1), ("ecos", 0)):
        trace = run_engine(engine, package)
        assert np.abs(trace["ship.psi"] - python["ship.psi"][first:]).max() <= 1e-9, engine


def test_without_a_c_compiler_the_build_says_so_and_builds_the_rest(tmp_path, monkeypatch,
                                                                     capsys):
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))           # no cc, no gcc
    assert cli.main(["pd_autopilot_c", "guidance", "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "note: no C compiler found (set CC, or install gcc)" in captured.err
    assert (tmp_path / "guidance.fmu").is_file()
    assert not (tmp_path / "pd_autopilot_c.fmu").exists()


def test_a_nan_input_fails_the_c_autopilot_until_reset(c_autopilot, tmp_path):
    from cosim.core.fmi import FmuInstance
    from cosim.core.instance import FmuCallError

    fmu = FmuInstance(shutil.copy(c_autopilot, tmp_path / "c.fmu"), "c")
    try:
        fmu.initialize()
        fmu.set({"psi": float("nan")})
        with pytest.raises(FmuCallError) as failed:
            fmu.do_step(0.0, 0.1)
        assert failed.value.status == "error"
        assert "at t = 0: input psi = nan is not finite" in str(failed.value)
        assert math.isnan(fmu.get(["delta_c"])["delta_c"])
        fmu.set({"psi": 0.0})
        with pytest.raises(FmuCallError, match="input psi = nan is not finite"):
            fmu.do_step(0.0, 0.1)                # a valid input does not revive it
        fmu.reset()
        fmu.initialize()
        fmu.set({"psi": 0.1})
        fmu.do_step(0.0, 0.1)
        assert fmu.get(["delta_c"])["delta_c"] == pytest.approx(0.2)
    finally:
        fmu.free()


def test_the_walkthrough_shows_the_pid_exactly_as_it_is_built():
    doc = (ROOT / "docs" / "own_autopilot.md").read_text()
    shown = doc.split("```python\n", 1)[1].split("```", 1)[0]
    assert shown == (ROOT / "autopilot_fmu" / "pid_autopilot_slave.py").read_text()
