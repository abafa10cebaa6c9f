"""The ship FMU through FMI: conformance, equality with the in-process model, state, errors."""
from __future__ import annotations

import gc
import math
import subprocess
import sys
import textwrap

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from cosim.core.fmi import FmuInstance
from cosim.core.instance import FmuCallError
from fmukit.timebase import communication_point
from helpers import fmpy_cli, read_csv
from ship_fmu.vessel import Vessel, VesselParameters

OUTPUTS = ["x", "y", "psi", "u", "v", "r", "delta", "X_w", "Y_w", "N_w"]
DT = 0.1


@pytest.fixture
def ship(open_fmu) -> FmuInstance:
    return open_fmu("ship")


def rudder_program(k: int) -> float:
    return 0.3 * math.sin(0.05 * k) + (0.2 if k % 97 < 40 else -0.1)


def test_model_description_validates_with_units_and_dependencies(fmu_paths):
    assert validate_fmu(str(fmu_paths["ship"])) == []
    md = read_model_description(str(fmu_paths["ship"]))
    units = {u.name: [d.name for d in u.displayUnits] for u in md.unitDefinitions}
    assert {"m", "m/s", "rad", "rad/s", "N", "N.m", "s", "rev/s"} <= set(units)
    assert "deg" in units["rad"] and "deg/s" in units["rad/s"]
    for v in md.modelVariables:
        if v.type == "Real":
            assert v.unit in units, v.name
            assert v.displayUnit == {"rad": "deg", "rad/s": "deg/s"}.get(v.unit), v.name
    assert {o.variable.name for o in md.outputs} == set(OUTPUTS)
    assert all(o.dependencies == [] for o in md.outputs), "no direct feedthrough"
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate


def test_fmpy_simulate_on_defaults_runs_straight_at_0_3_m_per_s(fmu_paths, tmp_path):
    fmpy_cli("simulate", str(fmu_paths["ship"]), "--stop-time", "100",
              "--output-file", "out.csv", cwd=tmp_path)
    rows = read_csv(tmp_path / "out.csv")
    assert rows[-1]["time"] == pytest.approx(100.0)
    assert all(row["u"] == pytest.approx(0.300, abs=0.001) for row in rows)
    assert all(row["psi"] == 0.0 and row["v"] == 0.0 for row in rows)


def test_fmpy_simulate_with_an_input_file_drives_the_rudder(fmu_paths, tmp_path):
    (tmp_path / "in.csv").write_text('"time","delta_c"\n0,0\n10,0\n10,0.2\n60,0.2\n')
    fmpy_cli("simulate", str(fmu_paths["ship"]), "--stop-time", "60",
              "--input-file", "in.csv", "--output-file", "out.csv", cwd=tmp_path)
    rows = read_csv(tmp_path / "out.csv")
    assert rows[-1]["delta"] == pytest.approx(0.2)
    assert rows[-1]["psi"] < -0.5          # positive rudder: turn to port


@pytest.mark.parametrize("Hs", [0.0, 0.005])
def test_fmu_equals_the_in_process_model(ship, Hs):
    ship.initialize({"Hs": Hs, "wave_seed": 11})
    vessel = Vessel(VesselParameters(Hs=Hs, wave_seed=11))
    worst = 0.0
    for k in range(600):       # the in-process model at the FMUs' nanosecond time base
        t, delta_c = communication_point(0.0, k, DT), rudder_program(k)
        ship.set({"delta_c": delta_c})
        ship.do_step(t, DT)
        vessel.step(t, DT, delta_c)
        got = ship.get(OUTPUTS)
        worst = max(worst, *(abs(got[n] - getattr(vessel, n)) for n in OUTPUTS))
    assert worst <= 1e-12


def _run(ship: FmuInstance, k0: int, steps: int) -> list[dict[str, float]]:
    rows = []
    for k in range(k0, k0 + steps):
        ship.set({"delta_c": rudder_program(k)})
        ship.do_step(k * DT, DT)
        rows.append(ship.get(OUTPUTS))
    return rows


def test_saved_state_reproduces_the_run_bit_for_bit(ship, open_fmu):
    ship.initialize({"Hs": 0.005, "wave_seed": 5})
    _run(ship, 0, 100)
    state = ship.slave.getFMUstate()
    first = _run(ship, 100, 200)
    ship.slave.setFMUstate(state)
    assert _run(ship, 100, 200) == first

    serialized = ship.slave.serializeFMUstate(state)
    other = open_fmu("ship", "other")
    other.initialize({"Hs": 0.005, "wave_seed": 99})
    other.slave.setFMUstate(other.slave.deSerializeFMUstate(serialized))
    assert other.get(["Hs"]) == {"Hs": 0.005}
    assert _run(other, 100, 200) == first


@pytest.mark.parametrize("name", ["delta_c", "n1", "n2", "n3"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_input_fails_the_fmu_by_name_until_reset(ship, name, bad):
    ship.initialize()
    first = _run(ship, 0, 10)
    ship.reset()
    ship.initialize()
    _run(ship, 0, 5)
    ship.set({name: bad})
    with pytest.raises(FmuCallError) as refused:
        ship.do_step(5 * DT, DT)
    assert refused.value.status == "fatal"
    assert any(f"input {name} = {bad}" in m and "not finite" in m
               for m in refused.value.messages), refused.value.messages
    assert all(math.isnan(value) for value in ship.get(OUTPUTS).values())
    ship.set({name: 1.0 if name != "delta_c" else 0.0})
    with pytest.raises(FmuCallError) as again:  # failed: a valid input does not revive it
        ship.do_step(5 * DT, DT)
    assert any(f"input {name} = {bad}" in m for m in again.value.messages)
    ship.reset()
    ship.initialize()
    assert _run(ship, 0, 10) == first


@pytest.mark.parametrize("name, value", [
    ("Hs", -0.01), ("T0", 0.0), ("T0", -1.0), ("wave_components", 0),
    ("delta_max", 0.0), ("delta_rate_max", -1.0), ("u0", math.nan),
    ("h_max", 0.0), ("x0", math.inf),
])
def test_invalid_parameters_are_reported_by_name_and_fail_the_first_step(ship, name, value):
    with pytest.raises(FmuCallError) as reported:
        ship.initialize({name: value})
    error = reported.value
    assert (error.call, error.status) == ("exitInitializationMode", "OK but logged an error")
    assert any(m.startswith("[error]") and f"parameter {name}" in m for m in error.messages)
    assert all(math.isnan(v) for v in ship.get(OUTPUTS).values())
    with pytest.raises(FmuCallError) as refused:
        ship.do_step(0.0, DT)
    assert refused.value.status == "fatal"
    assert any(f"parameter {name}" in m for m in refused.value.messages)


@pytest.mark.parametrize("h", [0.0, -0.1, math.nan])
def test_bad_communication_steps_are_refused(ship, h):
    ship.initialize()
    with pytest.raises(FmuCallError) as refused:
        ship.do_step(0.0, h)
    assert refused.value.status == "fatal"
    assert any("communication step" in m for m in refused.value.messages)


def test_the_fmu_runs_on_its_bundled_code_alone(fmu_paths, tmp_path):
    """In a fresh interpreter that cannot see this repository, the FMU still runs."""
    script = textwrap.dedent(f"""
        import sys
        sys.path = [p for p in sys.path if p not in ("", {str(fmu_paths['ship'].parent.parent)!r})]
        sys.meta_path = [f for f in sys.meta_path if "editable" not in repr(f).lower()]
        import fmpy
        result = fmpy.simulate_fmu({str(fmu_paths['ship'])!r}, stop_time=5.0,
                                   start_values={{"Hs": 0.005}})
        import ship_fmu.vessel, fmukit.slave
        print(ship_fmu.vessel.__file__)
        print(fmukit.slave.__file__)
        print(result["u"][-1])
    """)
    out = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                         text=True, timeout=120, check=True).stdout.split()
    assert all("/resources/" in path for path in out[:2]), out
    assert 0.25 < float(out[2]) < 0.35


def test_setting_an_output_or_a_fixed_parameter_late_is_refused(ship):
    ship.initialize()
    with pytest.raises(FmuCallError) as refused:
        ship.set({"psi": 1.0})
    assert any("psi is an output" in m for m in refused.value.messages)
    with pytest.raises(FmuCallError) as refused:
        ship.set({"Hs": 0.01})
    assert any("parameter Hs is fixed" in m for m in refused.value.messages)
    assert ship.get(["psi", "Hs"]) == {"psi": 0.0, "Hs": 0.0}


def test_step_before_initialisation_is_refused(ship):
    with pytest.raises(FmuCallError) as refused:
        ship.do_step(0.0, DT)
    assert refused.value.status == "fatal"
    assert any("exitInitializationMode" in m for m in refused.value.messages)


def test_many_refusals_leave_the_host_alive(fmu_paths):
    """pythonfmu 0.7 frees objects on every exception; fmukit must compensate."""
    for i in range(25):
        instance = FmuInstance(fmu_paths["ship"], f"ship{i}")
        with pytest.raises(FmuCallError):
            instance.initialize({"Hs": -1.0})
        with pytest.raises(FmuCallError):
            instance.set({"x": 1.0})
        instance.free()
        gc.collect()


@pytest.mark.parametrize("name", ["psi0", "psi_w"])
def test_a_heading_beyond_its_range_is_refused_by_name(name):
    """9e307 rad made sin(2 beta) of the wave moment fail with a bare 'math domain error' at
    exitInitializationMode; the declared range refuses it before any FMU call."""
    from cosim import simulate

    with pytest.raises(ValueError, match=rf"ship\.{name} = 8\.98846567431158e\+307 is outside "
                                         "its declared range"):
        simulate("waves_pd", set={f"ship.{name}": 8.98846567431158e+307, "ship.Hs": 0.0625},
                 stop_time=1.0)
