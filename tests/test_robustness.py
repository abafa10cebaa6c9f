"""Failure behaviour: saved states, determinism, a failing FMU in the master, long runs,
and hosts that survive loading our FMUs.

The day at sea is long (a minute) and left out of the quick suite (without ``pytest --long``):
it is the only test of what a day does to the numbers; every model it runs is run by the
quick suite's other tests."""
from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import zipfile
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from cosim import run as run_command
from cosim import scenarios
from cosim.core.fmi import FmuInstance
from cosim.core.master import Master
from cosim.core.ssd import Component, Connection, SystemDescription, write_ssd
from cosim.interop.hosts import run as run_engine
from cosim.interop.ssp import export
from fmubuild.project import ROOT
from helpers import command
from fmukit.timebase import communication_point

# Inputs that drive each FMU through something worth restoring, by step k.
PROGRAMS = {
    "ship": lambda k: {"delta_c": 0.3 * math.sin(0.02 * k), "n1": 8.13, "n2": 7.0 + k % 3},
    "pd_autopilot": lambda k: {"psi": 0.01 * k, "r": 0.002, "psi_d": 0.7 if k > 30 else 0.0},
    "smc_autopilot": lambda k: {"psi": 0.004 * k, "r": 0.001, "psi_d": 0.7 if k > 30 else -3.0},
    "guidance": lambda k: {"x": 0.4 * k, "y": 0.2 * k},
    "manoeuvre": lambda k: {"psi": 0.5 * math.sin(0.05 * k)},
}
PARAMETERS = {"ship": {"Hs": 0.005, "wave_seed": 4}}


def _outputs(fmu: FmuInstance) -> list[str]:
    return [v.name for v in fmu.description.modelVariables if v.causality == "output"]


def _run(fmu: FmuInstance, name: str, k0: int, steps: int) -> list[dict]:
    rows = []
    for k in range(k0, k0 + steps):
        fmu.set(PROGRAMS[name](k))
        fmu.do_step(communication_point(0.0, k, 0.1), 0.1)
        rows.append(fmu.get(_outputs(fmu)))
    return rows


@pytest.mark.parametrize("name", list(PROGRAMS))
def test_a_restored_state_continues_bit_for_bit(open_fmu, name):
    fmu = open_fmu(name)
    fmu.initialize(PARAMETERS.get(name, {}))
    _run(fmu, name, 0, 60)
    state = fmu.slave.getFMUstate()
    data = fmu.slave.serializeFMUstate(state)
    reference = _run(fmu, name, 60, 80)
    fmu.slave.setFMUstate(state)
    assert _run(fmu, name, 60, 80) == reference
    again = fmu.slave.deSerializeFMUstate(data)
    assert fmu.slave.serializeFMUstate(again) == data          # round trip, byte for byte
    other = open_fmu(name, f"{name}_other")
    other.initialize()                                         # default parameters
    other.slave.setFMUstate(other.slave.deSerializeFMUstate(data))
    assert _run(other, name, 60, 80) == reference               # parameters travel too
    for s in (state, again):
        fmu.slave.freeFMUstate(s)


def _scenario_csv(tmp_path: Path, name: str) -> str:
    master = Master(scenarios.load(name))
    try:
        master.run().write_csv(tmp_path / "inprocess.csv")
    finally:
        master.free()
    return (tmp_path / "inprocess.csv").read_text()


def test_same_scenario_same_bits_across_runs_and_processes(fmu_paths, tmp_path):
    first = _scenario_csv(tmp_path, "waves_smc")
    assert _scenario_csv(tmp_path, "waves_smc") == first
    subprocess.run([sys.executable, "-m", "cosim.run", "waves_smc", "--out", str(tmp_path),
                    "--no-plot"], check=True, capture_output=True, cwd=ROOT, timeout=300)
    assert (tmp_path / "waves_smc.csv").read_text() == first
    other = command(run_command.main, "waves_smc", "--out", str(tmp_path / "seed"), "--no-plot",
                    "--set", "ship.wave_seed=1")                   # another sea, here
    assert other.returncode == 0, other.stderr
    assert (tmp_path / "seed" / "waves_smc.csv").read_text() != first


def test_same_bits_in_our_master_and_in_libcosim(fmu_paths, tmp_path):
    master = Master(scenarios.load("waves_smc"), coupling="jacobi")
    try:
        ours = master.run()
    finally:
        master.free()
    theirs = run_engine("libcosim", export("waves_smc", tmp_path),
                        signals=("ship.psi", "ship.r", "ship.delta", "ship.X_w", "ship.N_w"))
    for signal in ("ship.psi", "ship.r", "ship.delta", "ship.X_w", "ship.N_w"):
        np.testing.assert_array_equal(theirs[signal], ours[signal][1:])   # libcosim: from t_1


@pytest.fixture(scope="module")
def fault_fmu(faulty_fmu) -> Path:
    return faulty_fmu("fault")


def _zombies() -> list[int]:
    """Children of this process that exited and were never reaped."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[0] == "Z" and int(fields[1]) == os.getpid():
            found.append(int(stat.parent.name))
    return found


@pytest.mark.parametrize("fault, failing, message", [
    (1, "ship", "input delta_c = nan is not finite"),      # the program's output is NaN
    (3, "program", "RuntimeError: injected fault at t = 50.0"),   # its model raises
])
def test_a_failing_fmu_stops_the_run_cleanly(fmu_paths, fault_fmu, tmp_path, fault, failing,
                                             message):
    system = SystemDescription(
        "faulty", {"program": Component("program", str(fault_fmu), {"psi": ("input", "Real"),
                                                                       "delta_c": ("output",
                                                                                   "Real")},
                                        {"fault_time": 50.0, "fault": fault}),
                   "ship": Component("ship", str(fmu_paths["ship"]),
                                     {"delta_c": ("input", "Real"), "psi": ("output", "Real")})},
        [Connection("ship", "psi", "program", "psi"),
         Connection("program", "delta_c", "ship", "delta_c")],
        stop_time=100.0, report="none", description="a program that fails at 50 s")
    write_ssd(system, tmp_path / "faulty.ssd")
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    child = subprocess.run([sys.executable, "-m", "cosim.run", str(tmp_path / "faulty.ssd"),
                            "--out", str(tmp_path / "out"), "--no-plot"],
                           capture_output=True, text=True, cwd=ROOT, timeout=300,
                           env={**os.environ, "TMPDIR": str(scratch)})
    assert child.returncode == 1
    assert f"FMU '{failing}': doStep at t = 50 s returned fatal" in child.stderr
    assert message in child.stderr
    header, *rows = (tmp_path / "out" / "faulty.csv").read_text().splitlines()
    assert len(rows) == 500 and rows[-1].startswith("49.9,")     # every step before the fault
    assert list(scratch.iterdir()) == []                        # extracted FMUs removed
    assert _zombies() == []


@pytest.mark.long
def test_24_hours_in_waves_stay_finite_bounded_and_phase_accurate(fmu_paths):
    """A day at sea under the PD autopilot, in-process; the wave phases at t = 86400 s."""
    from cosim.ensemble.reference import initialise
    system = scenarios.load("waves_pd")
    system.components["guidance"].parameters["waypoints"] = "0,0;1e6,1e6"  # 45 deg to the waves
    with Master(system, backend="inprocess") as master:
        models = initialise(master, {}, 0).models
    ship, pd, guidance = models["ship"], models["autopilot"], models["guidance"]
    worst = {"|psi - psi_d| (rad)": 0.0, "|u|": 0.0, "|v|": 0.0, "|r|": 0.0}
    for k in range(864_000):
        t = communication_point(0.0, k, 0.1)
        psi_d = guidance.psi_d(ship.x, ship.y)
        ship.step(t, 0.1, pd.command(ship.psi, ship.r, psi_d))
        if k % 100 == 0 and k >= 6000:              # after the initial 45 deg turn
            worst["|psi - psi_d| (rad)"] = max(worst["|psi - psi_d| (rad)"], abs(ship.psi - psi_d))
            for name in ("u", "v", "r"):
                worst[f"|{name}|"] = max(worst[f"|{name}|"], abs(getattr(ship, name)))
    print(f"\n24 h in waves: worst {worst}; x = {ship.x:.1f} m, xi = {ship.xi:.1f} m")
    assert all(map(math.isfinite, (ship.x, ship.y, ship.psi, ship.u, ship.v, ship.r, ship.xi)))
    assert worst["|psi - psi_d| (rad)"] < 0.1 and worst["|r|"] < 0.05
    assert 0.2 < ship.u < 0.4 and ship.x > 15_000 and ship.y > 15_000
    # theta_i = omega_i t - k_i xi + phi_i in double, against the same inputs in exact
    # rational arithmetic: t is exact (integer nanoseconds), so only rounding remains.
    waves = ship.waves.components
    t = communication_point(0.0, 864_000, 0.1)
    theta = waves.omega * t - waves.k * ship.xi + waves.phase   # as WaveLoads computes it
    exact = [float(Fraction(w) * Fraction(t) - Fraction(k) * Fraction(ship.xi) + Fraction(p))
             for w, k, p in zip(waves.omega, waves.k, waves.phase)]
    assert np.max(np.abs(theta - exact)) < 1e-8


def test_the_fmi_call_sequence_is_enforced_by_name(open_fmu):
    from cosim.core.instance import FmuCallError
    fmu = open_fmu("ship")
    slave = fmu.slave

    def refused(call, function, *args, **kwargs) -> list[str]:
        with pytest.raises(FmuCallError) as error:
            fmu.call(call, function, *args, **kwargs)
        return error.value.messages

    assert "not allowed in phase 'instantiated'" in refused(
        "exit", slave.exitInitializationMode)[0]
    assert "phase 'instantiated'" in refused("doStep", slave.doStep, 0.0, 0.1)[0]
    assert "fmi2Terminate is not allowed" in refused("terminate", slave.terminate)[0]
    fmu.initialize()
    assert "fmi2EnterInitializationMode is not allowed" in refused(
        "enter", slave.enterInitializationMode)[0]
    assert "fmi2SetupExperiment is not allowed" in refused(
        "setup", slave.setupExperiment)[0]
    fmu.do_step(0.0, 0.1)
    fmu.call("terminate", slave.terminate)
    final = fmu.get(["x", "u"])                                # allowed after terminate
    assert final["x"] > 0.0
    assert "phase 'terminated'" in refused("doStep", slave.doStep, 0.1, 0.1)[0]
    assert "after terminate" in refused("set", slave.setReal, [0], [0.1])[0]
    fmu.reset()                                                # back to instantiated
    fmu.initialize()
    fmu.do_step(0.0, 0.1)


@pytest.fixture(scope="module")
def exit_heap_host(tmp_path_factory) -> tuple[Path, Path]:
    """The exit-time host of tests/exit_heap and its late allocator library, compiled."""
    folder = Path(__file__).parent / "exit_heap"
    library = tmp_path_factory.mktemp("exit_heap") / "late_malloc.so"
    subprocess.run(["gcc", "-shared", "-fPIC", "-o", str(library),
                    str(folder / "late_malloc.c")], check=True)
    return folder / "host.py", library


def _host_exit_status(host: tuple[Path, Path], fmu: Path) -> tuple[int, str]:
    child = subprocess.run([sys.executable, str(host[0]), str(fmu), str(host[1])],
                           capture_output=True, text=True, timeout=120)
    return child.returncode, child.stderr


@pytest.mark.parametrize("name", list(PROGRAMS))
def test_a_host_that_loaded_an_fmu_exits_with_its_heap_intact(fmu_paths, exit_heap_host,
                                                              name):
    status, err = _host_exit_status(exit_heap_host, fmu_paths[name])
    assert status == 0, err


def test_without_the_exit_fix_the_same_host_aborts(fmu_paths, exit_heap_host, tmp_path):
    """The check above can fail: pythonfmu 0.7.0's own binary corrupts the heap at exit."""
    from fmukit.pythonfmu07 import KNOWN_BINARIES

    known = next(iter(KNOWN_BINARIES.values()))
    offset, original, patched = known.offset, known.code, known.patched
    unfixed = tmp_path / "ship.fmu"
    with zipfile.ZipFile(fmu_paths["ship"]) as fixed, zipfile.ZipFile(unfixed, "w") as out:
        for info in fixed.infolist():
            data = fixed.read(info)
            if info.filename.startswith("binaries/linux64/"):
                assert data[offset:offset + len(patched)] == patched
                data = data[:offset] + original + data[offset + len(patched):]
            out.writestr(info, data)
    status, err = _host_exit_status(exit_heap_host, unfixed)
    assert status == -signal.SIGABRT and "corrupted" in err


def test_the_exit_fix_refuses_a_binary_it_does_not_know():
    from fmubuild.packaging import fix_exit

    with pytest.raises(RuntimeError, match="ship.so is not the pythonfmu 0.7.0 linux64 binary"):
        fix_exit(b"\x7fELF something else", "ship.fmu:binaries/linux64/ship.so")
