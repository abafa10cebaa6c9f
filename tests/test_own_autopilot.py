"""Your own autopilot: the port contract, --autopilot and --map, sweeps and SSP packages."""
from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest

from cosim import run as cli
from cosim import scenarios
from cosim.core.master import Master
from cosim.interop.hosts import run as run_engine
from cosim.interop.ssp import export
from cosim.scenarios.autopilot import AutopilotError, check_autopilot
from cosim.studies import campaign, sweep_task
from cosim.studies.sweep_spec import Spec
from helpers import fmu_variant

RENAMED = {"psi": "heading", "r": "yaw_rate", "psi_d": "course", "delta_c": "rudder"}
MAP = [f"--map={port}={name}" for port, name in RENAMED.items()]


def _rename(xml: str) -> str:
    for port, name in RENAMED.items():
        xml = xml.replace(f'name="{port}"', f'name="{name}"')
    return xml


@pytest.fixture(scope="module")
def foreign(fmu_paths, tmp_path_factory) -> dict[str, Path]:
    """The PID FMU dressed as other people's FMUs: other names, other units, broken."""
    folder, pid = tmp_path_factory.mktemp("foreign"), fmu_paths["pid_autopilot"]
    not_fmu = folder / "notes.fmu"
    not_fmu.write_text("not a zip")
    return {
        "renamed": fmu_variant(pid, folder / "heading_pilot.fmu", _rename),
        "degrees": fmu_variant(pid, folder / "deg_pilot.fmu", lambda x: re.sub(
            r'(name="psi".*?)unit="rad" displayUnit="deg"', r'\1unit="deg"', x, count=1,
            flags=re.S).replace("<UnitDefinitions>", '<UnitDefinitions><Unit name="deg"/>')),
        "model_exchange": fmu_variant(pid, folder / "me_pilot.fmu", lambda x: re.sub(
            r"<CoSimulation [^>]*/>", '<ModelExchange modelIdentifier="pid_autopilot"/>', x)),
        "windows_only": fmu_variant(pid, folder / "win_pilot.fmu", drop=("binaries/linux64",)),
        "no_python": fmu_variant(pid, folder / "broken_pilot.fmu",
                                 drop=("resources/pid_autopilot_slave.py",)),
        "not_fmu": not_fmu,
        "guidance": fmu_paths["guidance"],
    }


def _run(tmp_path: Path, *args: str) -> int:
    return cli.main([*args, "--out", str(tmp_path), "--no-plot"])


def test_an_autopilot_with_other_port_names_runs_through_map(foreign, tmp_path):
    assert _run(tmp_path / "ours", "waves_pid") == 0
    assert _run(tmp_path / "theirs", "waves_pd", "--autopilot", str(foreign["renamed"]),
                *MAP) == 0
    ours = np.genfromtxt(tmp_path / "ours" / "waves_pid.csv", delimiter=",", names=True)
    theirs = np.genfromtxt(tmp_path / "theirs" / "waves_pd-heading_pilot.csv", delimiter=",",
                           names=True)
    np.testing.assert_array_equal(theirs["shippsi"], ours["shippsi"])
    np.testing.assert_array_equal(theirs["autopilotrudder"], ours["autopilotdelta_c"])


@pytest.mark.parametrize("case, args, fragment", [
    ("renamed", [], "no port 'psi': expected a Real input in rad \\(ship heading\\)"),
    ("renamed", ["--map", "heading=psi"], "--map names 'heading', which is not a port"),
    ("degrees", [], "port 'psi' is in deg: expected rad; the interfaces are in SI units, "
                    "angles in radians: declare psi in rad and convert inside the FMU"),
    ("model_exchange", [], "is a model-exchange FMU only"),
    ("windows_only", [], "has no binary for this platform \\(linux64\\); it has win64"),
    ("renamed", MAP[:1] + ["--map", "r=Kp"], "port 'Kp' \\(for r\\) is of causality "
                                             "parameter and type Real: expected a Real input"),
    ("guidance", ["--map=psi=x", "--map=r=y", "--map=psi_d=x", "--map=delta_c=wp_index"],
     "port 'wp_index' \\(for delta_c\\) is of causality output and type Integer: expected a "
     "Real output in rad"),
    ("not_fmu", [], "notes.fmu is not an FMU"),
])
def test_an_fmu_that_breaks_the_contract_is_refused_by_name_and_nothing_runs(
        foreign, tmp_path, capsys, case, args, fragment):
    with pytest.raises(SystemExit) as refused:
        _run(tmp_path, "waves_pd", "--autopilot", str(foreign[case]), *args)
    assert refused.value.code == 2
    err = capsys.readouterr().err
    assert re.search(fragment, err) and str(foreign[case].name) in err, err
    assert "Traceback" not in err and not list(tmp_path.glob("*.csv"))


def test_an_autopilot_that_fails_to_instantiate_is_named(foreign, tmp_path, capsys):
    with pytest.raises(SystemExit) as refused:
        _run(tmp_path, "calm_pd", "--autopilot", str(foreign["no_python"]))
    assert refused.value.code == 2
    err = capsys.readouterr().err
    # the entry module the build writes imports the missing script: the trial's child names
    # the module (it used to die with SIGSEGV inside pythonfmu)
    assert re.search("broken_pilot.fmu: instantiating the FMU failed", err), err
    assert "No module named 'pid_autopilot_slave'" in err


def test_its_parameters_are_set_and_unknown_ones_listed(foreign, tmp_path, capsys):
    assert _run(tmp_path, "calm_pd", "--autopilot", str(foreign["renamed"]), *MAP,
                "--stop-time", "10", "--set", "autopilot.Ki=0.0") == 0
    assert _run(tmp_path, "calm_pd", "--autopilot", str(foreign["renamed"]), *MAP,
                "--stop-time", "10", "--set", "autopilot.Kx=1") == 2
    err = capsys.readouterr().err
    assert "has no variable 'Kx'; it has: heading, yaw_rate, course, rudder, z, Kp, Ki" in err


def test_all_adds_the_autopilot_to_tables_1_and_2(fmu_paths, tmp_path, capsys):
    assert _run(tmp_path, "--all", "--autopilot", str(fmu_paths["pid_autopilot"]),
                "--name", "PID", "--stop-time", "100") == 0
    out = capsys.readouterr().out
    tables = out[out.index("Table 1"):]
    assert re.search(r"Table 1.*PD controller.*SMC controller.*PID controller +[\d.]+ +[\d.]+ "
                     r"+[\d.]+ +\| +- +- +-\n.*Table 2", tables, flags=re.S)
    assert {p.name for p in tmp_path.iterdir()} == {
        "calm_pd", "calm_smc", "waves_pd", "waves_smc", "calm_pd-PID", "waves_pd-PID"}


def test_sweep_takes_an_autopilot_fmu_and_an_ssd_path(fmu_paths, foreign, tmp_path):
    copy = tmp_path / "copied.ssd"
    copy.write_bytes(scenarios.path("waves_pid").read_bytes())
    spec_path = tmp_path / "spec.toml"
    spec_path.write_text(f"""
        stop_time = 30
        [controllers]
        ssd = "copied.ssd"
        fmu = {{ autopilot = "{foreign['renamed']}", map = {RENAMED!r} }}
        [axes]
        wave_seed = [3]
    """.replace("'", '"').replace(":", " ="))
    spec = Spec.read(spec_path)
    rows = {r["controller"]: campaign.run_locally(spec, r) for r in spec.runs()}
    sweep_task.free_masters()
    assert rows["ssd"]["status"] == rows["fmu"]["status"] == "ok"
    assert rows["ssd"]["J"] == rows["fmu"]["J"]          # the same PID, the same sea


def test_sweep_refuses_a_controller_that_breaks_the_contract(foreign, tmp_path):
    spec_path = tmp_path / "spec.toml"
    spec_path.write_text(f'[controllers]\nbad = "{foreign["degrees"]}"\n')
    with pytest.raises(ValueError, match="(?s)controller 'bad': .*port 'psi' is in deg"):
        Spec.read(spec_path)


def test_exported_package_carries_the_autopilot_and_runs_in_libcosim(foreign, tmp_path):
    package = export("waves_pd", tmp_path, autopilot=foreign["renamed"],
                     port_map=RENAMED)
    assert package.name == "waves_pd-heading_pilot.ssp"
    with zipfile.ZipFile(package) as ssp:
        assert "resources/heading_pilot.fmu" in ssp.namelist()
    trace = run_engine("libcosim", package, signals=("ship.psi", "autopilot.rudder"))
    master = Master(scenarios.load("waves_pd", foreign["renamed"], RENAMED),
                    coupling="jacobi")
    try:
        ours = master.run()
    finally:
        master.free()
    np.testing.assert_array_equal(trace["ship.psi"], ours["ship.psi"][1:])


def test_check_autopilot_accepts_every_autopilot_of_the_project(fmu_paths):
    for name in ("pd_autopilot", "smc_autopilot", "pid_autopilot"):
        assert check_autopilot(fmu_paths[name]).coSimulation is not None
    with pytest.raises(AutopilotError, match="no port 'psi'"):
        check_autopilot(fmu_paths["guidance"])


@pytest.mark.parametrize("setting, fragment", [
    ("autopilot.Kp=1e9", "autopilot.Kp = '1e9' is outside its declared range"),
    ("autopilot.Ki=nan", "autopilot.Ki = 'nan' is not a number (NaN)"),
])
def test_a_bad_parameter_of_the_autopilot_is_named(fmu_paths, tmp_path, capsys, setting,
                                                   fragment):
    """Checked against the user's FMU's own declaration before it is instantiated."""
    assert _run(tmp_path, "calm_pd", "--autopilot", str(fmu_paths["pid_autopilot"]),
                "--set", setting) == 2
    err = capsys.readouterr().err
    assert [line for line in err.splitlines() if line.startswith("error:")] == [
        f"error: {fragment}; autopilot.{setting[10:12]} is a finite Real, from -10000.0 to "
        "10000.0"]


def test_the_in_process_backend_runs_a_foreign_fmu_through_fmi_and_says_so(foreign, tmp_path,
                                                                         capsys):
    assert _run(tmp_path, "calm_pd", "--autopilot", str(foreign["renamed"]), *MAP,
                "--backend", "inprocess", "--stop-time", "20") == 0
    err = capsys.readouterr().err
    assert ("note: autopilot (heading_pilot.fmu) runs through FMI, not in-process: its "
            "ModelVariables differ from those its class "
            "autopilot_fmu.pid_autopilot_slave.PIDAutopilotSlave declares") in err
    meta = json.loads(next(tmp_path.glob("*.json")).read_text())
    assert meta["backends"] == {"guidance": "inprocess", "autopilot": "fmi",
                                "ship": "inprocess"}


def test_a_map_that_wires_two_ports_onto_one_variable_is_refused(fmu_paths):
    """Issue 38: two connections into one input are refused in an .ssd; so through --map."""
    with pytest.raises(AutopilotError, match="--map wires psi and psi_d onto one variable "
                                             "\\(psi\\); each port needs its own"):
        check_autopilot(fmu_paths["pd_autopilot"], {"psi_d": "psi"})
