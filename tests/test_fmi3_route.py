"""The master on FMI 3.0: every scenario through the FMI 3.0 twins equals the FMI 2.0 route bit
for bit, on both couplings and both backends; mixed versions, .ssd files naming the twins,
the command line, and a user's FMI 3.0 autopilot checked against the same contract.

The quick suite (without ``pytest --long``) runs each scenario through the twins once, on the
couplings and backends in turn (``ROUTES``, shifted by one at each round, so that a
controller's calm and waves runs take different backends): every scenario once, and every
coupling on every backend at least twice."""
from __future__ import annotations

import re
import shutil
import zipfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from cosim import run as cli
from cosim import scenarios, simulate
from cosim import _cli
from cosim.core.fmi import FmuInstance, read_description
from cosim.core.instance import FmuCallError
from cosim.core.master import Master
from cosim.core.ssd import read_ssd, write_ssd
from cosim.core.system import with_fmi
from cosim.scenarios.autopilot import AutopilotError, check_autopilot
from fmubuild import project
from fmubuild.project import FMU_DIRS, FMUS
from helpers import fmu_variant, recorded

ROUTES = [(c, b) for c in ("gauss-seidel", "jacobi") for b in ("fmi", "inprocess")]
"""Each coupling on each backend."""


@pytest.fixture(scope="module", autouse=True)
def twins(fmu_paths, fmi3_paths) -> dict[str, Path]:
    """Both versions of every FMU built from this checkout."""
    return fmi3_paths


def run(name: str, fmi: int, coupling: str = "gauss-seidel", backend: str = "fmi"):
    """A recorded run of a scenario on this project's FMUs of one FMI version, cached for
    the session (``helpers.recorded``)."""
    return recorded(name, fmi, coupling, backend)


def assert_same_bits(a, b) -> None:
    """The same columns, units, times and values, to the last bit (NaN included)."""
    assert a.columns == b.columns and a.units == b.units
    assert a.rows == b.rows > 1000
    assert np.array_equal(a.t.view(np.uint64), b.t.view(np.uint64))
    differ = [c for i, c in enumerate(a.columns)
              if not np.array_equal(a.data[:, i].view(np.uint64), b.data[:, i].view(np.uint64))]
    assert not differ, differ
    assert a.meta["parameters"] == b.meta["parameters"]


@pytest.mark.parametrize("name, coupling, backend", [
    pytest.param(name, *route, marks=() if j == (i + i // len(ROUTES)) % len(ROUTES)
                 else pytest.mark.long)
    for i, name in enumerate(scenarios.names()) for j, route in enumerate(ROUTES)])
def test_every_scenario_through_fmi3_equals_fmi2_bit_for_bit(name, coupling, backend):
    fmi3 = run(name, 3, coupling, backend)
    assert_same_bits(fmi3, run(name, 2, coupling, "fmi"))
    assert set(fmi3.meta["backends"].values()) == {backend}, fmi3.meta["notes"]
    files = [Path(f["file"]) for f in fmi3.meta["fmus"].values()]
    assert files and all(f.parent == FMU_DIRS[3] for f in files)


def test_each_instance_is_of_its_fmus_version_and_matched_by_name(twins, fmu_paths):
    """FMI 3.0's value references are FMI 2.0's plus one (time is 0): the master wires
    by name, so both give the same run."""
    two, three = FmuInstance(fmu_paths["ship"], "ship"), FmuInstance(twins["ship"], "ship")
    try:
        assert (two.fmi_version, three.fmi_version) == (2, 3)
        assert list(two.variables) == list(three.variables)      # no "time" among them
        assert all(three.vr(n) == two.vr(n) + 1 for n in two.variables)
        assert {n: v.type for n, v in three.variables.items()} == \
            {n: v.type for n, v in two.variables.items()}         # Float64 read as Real
        assert three.feedthrough == two.feedthrough
        assert {n: three.unit(n) for n in three.variables} == \
            {n: two.unit(n) for n in two.variables}
    finally:
        two.free()
        three.free()
    assert read_description(twins["ship"], "ship").fmiVersion == "3.0"


def test_the_ship_twins_state_is_saved_restored_and_moved_by_the_fmi2_call_names(twins):
    """The master's call names are FMI 2.0's (getFMUstate, ...); an FMI 3.0 instance maps
    them to FMI 3.0's (getFMUState, ...): a state restored, or deserialised into another
    instance, gives the same steps to the last bit."""
    ship, other = FmuInstance(twins["ship"], "ship"), FmuInstance(twins["ship"], "other")
    outputs = [n for n, v in ship.variables.items() if v.causality == "output"]

    def steps(fmu, k0: int) -> list[dict]:
        rows = []
        for k in range(k0, k0 + 20):
            fmu.set({"delta_c": 0.3})
            fmu.do_step(k * 0.1, 0.1)
            rows.append(fmu.get(outputs))
        return rows
    try:
        for fmu in (ship, other):
            fmu.initialize()
        steps(ship, 0)
        state = ship.call("getFMUstate", ship.fmi("getFMUstate"))
        ahead = steps(ship, 20)
        ship.call("setFMUstate", ship.fmi("setFMUstate"), state)
        assert steps(ship, 20) == ahead
        ship.call("setFMUstate", ship.fmi("setFMUstate"), state)
        data = ship.call("serializeFMUstate", ship.fmi("serializeFMUstate"), state)
        other.call("setFMUstate", other.fmi("setFMUstate"),
                   other.call("deSerializeFMUstate", other.fmi("deSerializeFMUstate"), data))
        assert steps(other, 20) == ahead
        ship.call("freeFMUstate", ship.fmi("freeFMUstate"), state)
    finally:
        ship.free()
        other.free()


@pytest.mark.parametrize("backend", ["fmi", "inprocess"])
def test_a_reset_master_runs_the_twins_again_to_the_same_bits(backend):
    with Master(scenarios.load("waves_pd", fmi=3), backend=backend) as master:
        first = master.run(150.0)
        master.reset()
        assert_same_bits(master.run(150.0), first)


@pytest.mark.parametrize("backend", ["fmi", "inprocess"])
def test_mixed_versions_in_one_system_run_as_either(twins, backend):
    system = scenarios.load("waves_pd")
    system.components["autopilot"].source = str(twins["pd_autopilot"])
    with Master(system, backend=backend) as master:
        mixed = master.run()
    assert mixed.error is None
    assert set(mixed.meta["backends"].values()) == {backend}, mixed.meta["notes"]
    assert Path(mixed.meta["fmus"]["autopilot"]["file"]).parent == FMU_DIRS[3]
    assert Path(mixed.meta["fmus"]["ship"]["file"]).parent == FMU_DIRS[2]
    assert_same_bits(mixed, run("waves_pd", 2))


def test_an_ssd_that_names_fmi3_fmus_runs_them_also_when_copied_elsewhere(tmp_path):
    """Its sources point into fmus/fmi3/; copied away from the checkout, the search path
    finds them by their path after fmus/ (fmi3/ship.fmu), not the FMI 2.0 ship.fmu."""
    system = read_ssd(scenarios.path("calm_pd"))
    named = {c: f"../../fmus/fmi3/{Path(system.components[c].source).name}"
             for c in system.components}
    write_ssd(system, tmp_path / "calm_pd_fmi3.ssd", named)
    with Master(scenarios.load(tmp_path / "calm_pd_fmi3.ssd")) as master:
        assert {(type(i), i.fmi_version) for i in master.instances.values()} == \
            {(FmuInstance, 3)}
        assert_same_bits(master.run(), run("calm_pd", 2))
    back = with_fmi(scenarios.load(tmp_path / "calm_pd_fmi3.ssd"), 2)
    assert {Path(back.fmu_path(c)).parent for c in back.components} == {FMU_DIRS[2]}


def test_with_fmi_leaves_a_users_own_fmu_alone(tmp_path, fmu_paths):
    mine = shutil.copy(fmu_paths["pd_autopilot"], tmp_path / "pd_autopilot.fmu")
    system = scenarios.load("calm_pd")
    system.components["autopilot"].source = str(mine)
    switched = with_fmi(system, 3)
    assert switched.fmu_path("autopilot") == Path(mine)
    assert switched.fmu_path("ship") == FMU_DIRS[3] / "ship.fmu"
    with pytest.raises(ValueError, match="FMI 4: this project's FMUs are built for FMI 2.0 "
                                         "and 3.0"):
        with_fmi(system, 4)


def test_a_missing_twin_says_how_to_build_the_fmi3_fmus(tmp_path, monkeypatch, capsys):
    unbuilt = {**FMU_DIRS, 3: tmp_path / "fmi3"}
    monkeypatch.setattr(project, "FMU_DIRS", unbuilt)
    monkeypatch.setattr(_cli, "FMU_DIRS", unbuilt)
    assert cli.main(["calm_pd", "--fmi", "3", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"tried {tmp_path / 'fmi3' / 'guidance.fmu'}; one of this project's FMI 3.0 FMUs, " \
           "not built" in err
    assert err.endswith("\n  build the FMUs with: python -m fmukit.build --fmi 3\n"), err


def test_the_command_line_runs_the_twins_with_the_same_csv(tmp_path, capsys):
    for fmi in ("2", "3"):
        assert cli.main(["calm_pd", "--fmi", fmi, "--stop-time", "50", "--no-plot",
                         "--out", str(tmp_path / fmi)]) == 0
    capsys.readouterr()
    assert (tmp_path / "2" / "calm_pd.csv").read_bytes() == \
        (tmp_path / "3" / "calm_pd.csv").read_bytes()
    assert "/fmus/fmi3/ship.fmu" in (tmp_path / "3" / "calm_pd.json").read_text()


def test_simulate_takes_the_version():
    fmi3 = simulate("calm_pd", stop_time=50, fmi=3)
    assert fmi3.meta["fmus"]["ship"]["file"] == str(FMU_DIRS[3] / "ship.fmu")
    assert np.array_equal(fmi3.data, simulate("calm_pd", stop_time=50, fmi=2).data)


def test_a_step_that_asks_to_end_the_simulation_fails_the_run(twins, monkeypatch):
    """FMI 3.0's terminateSimulation, through ``do_step`` and the master's prepared step
    (both the raw fmi3DoStep): the run cannot go on without that FMU."""
    def asks_to_end(instance, t, h, no_earlier_state, event, terminate, early, last) -> int:
        terminate._obj.value = True
        return 0                                        # fmi3OK

    fmu = FmuInstance(twins["pd_autopilot"], "autopilot")
    said = "doStep at t = 0 s returned OK but asked to end the simulation"
    try:
        fmu.initialize()
        with monkeypatch.context() as patch:
            patch.setattr(fmu.slave, "dll", SimpleNamespace(fmi3DoStep=asks_to_end))
            with pytest.raises(FmuCallError, match=said):
                fmu.do_step(0.0, 0.1)
            step = fmu.stepper()
            with pytest.raises(FmuCallError, match=said):
                step(0.0, 0.1)
    finally:
        fmu.free()


# -- a user's FMI 3.0 autopilot: the same contract ----------------------------------
def test_an_fmi3_autopilot_keeps_the_contract_and_runs(twins):
    assert check_autopilot(twins["pd_autopilot"], trial=True).fmiVersion == "3.0"
    mine = simulate("calm_pd", autopilot=twins["pd_autopilot"], stop_time=50)
    assert np.array_equal(mine["ship.psi"], simulate("calm_pd", stop_time=50)["ship.psi"])


def test_an_fmi3_autopilot_breaking_the_contract_is_told_every_port_at_once(twins, tmp_path):
    def broken(text: str) -> str:
        text = text.replace('name="psi_d"', 'name="psid"')                 # no psi_d
        text = re.sub(r'<Float64 (name="r" [^>]*?) variability="continuous" start="0.0" '
                      r'unit="rad/s"[^>]*/>', r'<Int32 \1 variability="discrete" start="0"/>',
                      text)                                                 # an Int32 r
        return re.sub(r'(name="psi" .*?)unit="rad" displayUnit="deg"', r'\1unit="deg"', text,
                      count=1, flags=re.S).replace("<UnitDefinitions>",
                                                   '<UnitDefinitions><Unit name="deg"/>')
    fmu = fmu_variant(twins["pd_autopilot"], tmp_path / "broken.fmu", xml=broken)
    with pytest.raises(AutopilotError) as refused:
        check_autopilot(fmu)
    message = str(refused.value)
    assert "contract of an FMI 3.0 FMU (Float64 inputs psi (rad), r (rad/s)" in message
    assert "no port 'psi_d': expected a Float64 input in rad (desired course)" in message
    assert "port 'r' is of causality input and type Int32: expected a Float64 input" in message
    assert "port 'psi' is in deg: expected rad" in message
    assert "It has inputs: psi (Float64, deg), r (Int32), psid (Float64, rad)" in message


@pytest.mark.parametrize("edit, says", [
    (lambda t: t.replace('fmiVersion="3.0"', 'fmiVersion="3.1"'),
     "is an FMI 3.1 FMU; an autopilot must be an FMI 2.0 or 3.0 co-simulation FMU"),
    (lambda t: t.replace("<CoSimulation", "<ModelExchange").replace(
        "</CoSimulation>", "</ModelExchange>"),
     "is a model-exchange FMU only; an autopilot must be an FMI 2.0 or 3.0 co-simulation FMU"),
])
def test_other_versions_and_kinds_are_refused_clearly(twins, tmp_path, edit, says):
    fmu = fmu_variant(twins["pd_autopilot"], tmp_path / "other.fmu", xml=edit)
    with pytest.raises(AutopilotError, match=says):
        check_autopilot(fmu)


def test_every_twin_is_fmi3_and_found_where_the_scenarios_look(twins):
    assert set(FMUS) <= set(twins)
    for name in FMUS:
        with zipfile.ZipFile(twins[name]) as fmu:
            assert b'fmiVersion="3.0"' in fmu.read("modelDescription.xml")


@pytest.mark.parametrize("overrides", [      # judged by the FMU at exitInitializationMode
    {"guidance": {"waypoints": "0,0;nan,1"}},
    {"ship": {"Hs": 0.1, "T0": 0.2}}])
def test_both_backends_refuse_what_the_twins_refuse_with_the_same_words(overrides):
    errors = []
    for backend in ("fmi", "inprocess"):
        with Master(scenarios.load("calm_pd", fmi=3), backend=backend,
                    overrides=overrides) as master:
            errors.append(master.run(5.0).error)
    name, value = next(iter(next(iter(overrides.values())).items()))
    assert f"{name} = {value}" in errors[0] or f"{name}: " in errors[0], errors[0]
    assert errors[0] == errors[1]


def test_a_step_refused_on_fmi3_is_an_error_not_fatal_on_both_backends(monkeypatch):
    """FMI 3.0 lets doStep refuse without fmi3Fatal: the master reports fmi3Error from either
    backend, with the FMU's words (the twins run this process's modules: the fault is
    injected into both)."""
    from ship_fmu.vessel import Vessel
    step = Vessel.step

    def failing_step(self, t, h, delta_c, *args):
        if t >= 5.0:
            raise ValueError("injected fault")
        return step(self, t, h, delta_c, *args)
    monkeypatch.setattr(Vessel, "step", failing_step)
    errors = []
    for backend in ("fmi", "inprocess"):
        with Master(scenarios.load("calm_pd", fmi=3), backend=backend) as master:
            recording = master.run(10.0)
        assert recording.rows == 50
        errors.append(recording.error)
    assert errors[0].startswith("FMU 'ship': doStep at t = 5 s returned error\n"), errors[0]
    assert "injected fault" in errors[0]
    assert errors[0] == errors[1]
