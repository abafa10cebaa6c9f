"""The C autopilot's FMI 3.0 twin: what it declares, what it computes and what it refuses, each
against its FMI 2.0 twin (and the Python PD's results); what it exports and carries."""
from __future__ import annotations

import ctypes
import math
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import (FMU3Slave, fmi3Boolean, fmi3Float64, fmi3InstanceEnvironment,
                       fmi3LogMessageCallback, fmi3ValueReference)
from fmpy.validation import validate_fmu

from fmubuild import cbuild
from fmubuild.crosscheck import files

NAME = "pd_autopilot_c"
FMI3_FUNCTIONS = tuple(re.findall(
    r"^#define (fmi3\w+)\s+fmi3FullName\(", (Path(fmpy.__file__).parent / "c-code" /
                                              "fmi3Functions.h").read_text(), re.MULTILINE))
"""Every function of fmi3Functions.h, which an FMI 3.0 FMU must export (FMI 3.0.2, 2.5)."""


@pytest.fixture(scope="module")
def twins(fmu_paths, fmi3_paths) -> dict[int, Path]:
    """FMI version: the C autopilot of that version, current; skipped without a compiler."""
    if NAME not in fmi3_paths:
        pytest.skip("no C compiler on this machine (set CC or install gcc)")
    return {2: fmu_paths[NAME], 3: fmi3_paths[NAME]}


@pytest.fixture(scope="module")
def c3(twins) -> Path:
    """The FMI 3.0 twin."""
    return twins[3]


def test_it_validates_and_carries_its_binaries_and_sources(c3):
    assert validate_fmu(str(c3)) == []
    with zipfile.ZipFile(c3) as package:
        names = set(package.namelist())
        build = package.read("sources/buildDescription.xml").decode()
    assert f"binaries/x86_64-linux/{NAME}.so" in names
    assert {f"sources/{NAME}_fmi3.c", "sources/pd_law.h", "sources/buildDescription.xml"} \
        <= names
    assert not {n for n in names if n.startswith("binaries/") and "linux64" in n}
    assert not {n for n in names if re.search(r"sources/fmi\d", n)}   # the host's headers
    assert f'<SourceFile name="{NAME}_fmi3.c"/>' in build


def test_it_exports_every_fmi3_function(c3, tmp_path):
    with zipfile.ZipFile(c3) as package:
        package.extract(f"binaries/x86_64-linux/{NAME}.so", tmp_path)
    library = ctypes.CDLL(str(tmp_path / "binaries" / "x86_64-linux" / f"{NAME}.so"))
    assert len(FMI3_FUNCTIONS) == 75 and "fmi3ActivateModelPartition" in FMI3_FUNCTIONS
    assert [f for f in FMI3_FUNCTIONS if not hasattr(library, f)] == []


def test_the_law_is_written_once_and_both_entry_points_include_it():
    folder = cbuild.ROOT / cbuild.C_FMUS[NAME]
    entry_points = [cbuild.sources(NAME, fmi)[0] for fmi in (2, 3)]
    assert [p.name for p in entry_points] == [f"{NAME}.c", f"{NAME}_fmi3.c"]
    for source in entry_points:
        text = source.read_text()
        assert '#include "pd_law.h"' in text and "remainder(" not in text, source
    assert (folder / "pd_law.h").read_text().count("remainder(") == 1


def test_it_declares_what_its_fmi2_twin_declares(twins):
    fmi2, fmi3 = (read_model_description(str(twins[v])) for v in (2, 3))
    two = {v.name: v for v in fmi2.modelVariables}
    three = {v.name: v for v in fmi3.modelVariables}
    assert list(three) == [*two, "time"]
    for name, v2 in two.items():
        v3 = three[name]
        assert (v3.type, v2.type) == ("Float64", "Real")
        assert v3.valueReference == v2.valueReference + 1, name
        for attribute in ("causality", "variability", "initial", "start", "unit",
                          "displayUnit", "description"):
            assert getattr(v3, attribute) == getattr(v2, attribute), (name, attribute)
    time = three["time"]
    assert (time.valueReference, time.causality, time.unit) == (0, "independent", "s")

    def by_name(description):
        return {u.variable.name: [d.name for d in u.dependencies]
                for u in description.outputs}

    assert by_name(fmi3) == by_name(fmi2) == {"delta_c": ["psi", "r", "psi_d"]}
    assert [(u.name, u.baseUnit.rad, u.baseUnit.s, [(d.name, d.factor) for d in u.displayUnits])
            for u in fmi3.unitDefinitions] == [
        (u.name, u.baseUnit.rad, u.baseUnit.s, [(d.name, d.factor) for d in u.displayUnits])
        for u in fmi2.unitDefinitions]
    experiment = ("startTime", "stopTime", "stepSize")
    assert [getattr(fmi3.defaultExperiment, a) for a in experiment] == \
        [getattr(fmi2.defaultExperiment, a) for a in experiment]
    assert (fmi3.description, fmi3.coSimulation.modelIdentifier) == \
        (fmi2.description, fmi2.coSimulation.modelIdentifier)
    assert fmi3.coSimulation.canHandleVariableCommunicationStepSize
    assert not fmi3.coSimulation.canGetAndSetFMUstate and not fmi2.coSimulation.canGetAndSetFMUstate
    assert fmi3.modelExchange is None and fmi3.scheduledExecution is None


def test_its_value_references_are_the_python_pds_fmi3_ones(c3, fmi3_paths):
    ours = {v.name: v.valueReference for v in read_model_description(str(c3)).modelVariables}
    theirs = {v.name: v.valueReference for v in
              read_model_description(str(fmi3_paths["pd_autopilot"])).modelVariables}
    assert ours == theirs


def _wrapping_inputs(path: Path) -> Path:
    """Inputs for 60 s whose heading error wraps, one way or the other, at most steps."""
    t = np.round(np.arange(0, 601) * 0.1, 10)
    rng = np.random.default_rng(20)
    psi = np.cumsum(rng.normal(0.0, 0.4, t.size))
    r = rng.normal(0.0, 0.02, t.size)
    psi_d = rng.uniform(-4.0, 4.0, t.size)
    psi[100], psi_d[100] = 0.0, math.pi                  # an error of -pi, wrapped to pi
    rows = "\n".join(",".join(repr(float(x)) for x in row) for row in zip(t, psi, r, psi_d))
    path.write_text('"time","psi","r","psi_d"\n' + rows + "\n")
    return path


def _delta_c(fmu: Path, inputs: Path, stop: float, cwd: Path) -> bytes:
    """delta_c at every step of ``fmpy simulate``, as the CSV it writes, in a child process
    isolated from this checkout (a Python FMU runs the modules it carries)."""
    out = cwd / f"{fmu.parent.name}_{fmu.stem}.csv"
    subprocess.run([sys.executable, "-I", "-m", "fmpy.cli", "simulate", str(fmu),
                    "--stop-time", repr(stop), "--output-interval", "0.1", "--input-file",
                    str(inputs), "--output-variables", "delta_c", "--output-file", str(out)],
                   cwd=cwd, check=True, capture_output=True, text=True, timeout=120)
    return out.read_bytes()


@pytest.mark.parametrize("inputs", ["crosscheck", "wrapping"])
def test_it_computes_what_its_fmi2_twin_and_the_python_pd_do_to_the_last_bit(
        twins, fmu_paths, fmi3_paths, tmp_path, inputs):
    path, stop = ((files("pd_autopilot")["in"], 30.0) if inputs == "crosscheck" else
                  (_wrapping_inputs(tmp_path / "wrapping.csv"), 60.0))
    results = {label: _delta_c(fmu, path, stop, tmp_path) for label, fmu in (
        ("C, FMI 3.0", twins[3]), ("C, FMI 2.0", twins[2]),
        ("Python, FMI 2.0", fmu_paths["pd_autopilot"]),
        ("Python, FMI 3.0", fmi3_paths["pd_autopilot"]))}
    reference = results.pop("C, FMI 3.0")
    values = np.genfromtxt(reference.splitlines(), delimiter=",", names=True)["delta_c"]
    assert len(values) == 10 * stop + 1 and np.ptp(values) > 1.0
    assert {label: result == reference for label, result in results.items()} == \
        {label: True for label in results}


class Twin:
    """One version's C autopilot instantiated through fmpy, by variable name, with the
    statuses and log messages of its calls (logging off, as a host leaves it)."""

    def __init__(self, fmu: Path, fmi: int, folder: Path):
        description = read_model_description(str(fmu))
        self.fmi, self.messages = fmi, []
        self.vr = {v.name: v.valueReference for v in description.modelVariables}
        unzipped = fmpy.extract(str(fmu), str(folder))
        kind = FMU2Slave if fmi == 2 else FMU3Slave
        self.slave = kind(guid=description.guid, unzipDirectory=unzipped, instanceName="c",
                          modelIdentifier=description.coSimulation.modelIdentifier)
        if fmi == 2:
            self.callbacks = fmi2CallbackFunctions()
            self.callbacks.logger = fmi2CallbackLoggerTYPE(
                lambda env, name, status, category, message: self.messages.append(
                    (status, message.decode())))
            self.slave.instantiate(callbacks=self.callbacks)
        else:
            self.slave.instantiate(logMessage=lambda env, status, category, message:
                                   self.messages.append((status, message.decode())))

    def call(self, function: str, *args) -> tuple[int, list[str]]:
        """The status of ``function`` (fmpy's name) called with ``args``, and its messages."""
        self.messages.clear()
        try:
            getattr(self.slave, function)(*args)
            status = 0
        except FMICallException as failed:
            status = failed.status
        return status, [m for _, m in self.messages]

    def set(self, **values: float) -> tuple[int, list[str]]:
        function = "setReal" if self.fmi == 2 else "setFloat64"
        return self.call(function, [self.vr[n] for n in values], list(values.values()))

    def get(self, name: str) -> float:
        getter = self.slave.getReal if self.fmi == 2 else self.slave.getFloat64
        return getter([self.vr[name]])[0]

    def enter_initialization(self) -> None:
        if self.fmi == 2:
            self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()

    def initialize(self) -> None:
        self.enter_initialization()
        self.slave.exitInitializationMode()

    def step(self, t: float, h: float) -> tuple[int, list[str]]:
        return self.call("doStep", t, h)


def _refusals(twin: Twin) -> list[tuple[int, list[str]]]:
    """What the twin answers to each call of one refused call sequence."""
    answers = [twin.step(0.0, 0.1)]                         # before initialization
    twin.enter_initialization()
    twin.set(Kp=math.inf)
    answers.append(twin.call("exitInitializationMode"))     # a parameter not finite
    twin.call("reset")
    twin.initialize()
    answers += [twin.set(Kp=1.0),                           # fixed after initialization
                twin.set(delta_c=0.0),                      # an output
                twin.step(0.0, 0.0),                        # no step
                twin.set(r=math.nan), twin.step(0.0, 0.1),  # fails the FMU
                twin.set(r=0.0), twin.step(0.1, 0.1),       # and it stays failed
                twin.call("terminate")]
    return answers


def test_it_refuses_what_its_fmi2_twin_refuses_with_the_same_messages(twins, tmp_path):
    answers = {}
    for fmi in (2, 3):
        twin = Twin(twins[fmi], fmi, tmp_path / str(fmi))
        answers[fmi] = _refusals(twin)
        assert math.isnan(twin.get("delta_c")) and twin.get("Kp") == 2.0
        twin.slave.freeInstance()
    error = 3                                               # fmi2Error, fmi3Error
    failed = ("c: doStep at t = 0: input r = nan is not finite; the FMU has failed (delta_c "
              "reads NaN until fmi3Reset)")
    assert answers[3] == [
        (error, ["c: fmi3DoStep is only allowed after fmi3ExitInitializationMode"]),
        (error, ["c: parameter Kp is not finite"]),
        (error, ["c: parameter Kp is fixed after initialization"]),
        (error, ["c: value reference 4 is not an input or parameter"]),
        (error, ["c: doStep with a communication step of 0 s"]),
        (0, []),
        (error, [failed]),
        (0, []),
        (error, [failed]),
        (0, [])]
    fmi2_names = [(status, [m.replace("fmi3", "fmi2").replace("reference 4", "reference 3")
                            for m in messages]) for status, messages in answers[3]]
    assert answers[2] == fmi2_names


@pytest.fixture
def twin3(twins, tmp_path):
    twin = Twin(twins[3], 3, tmp_path)
    yield twin
    twin.slave.freeInstance()


def test_a_reset_revives_it_and_its_time_is_the_hosts(twin3):
    twin3.initialize()
    twin3.set(psi=math.nan)
    assert twin3.step(0.0, 0.1)[0] == 3
    assert twin3.call("reset") == (0, [])
    twin3.slave.enterInitializationMode(startTime=5.0)
    assert twin3.get("time") == 5.0
    twin3.slave.exitInitializationMode()
    twin3.set(psi=0.1)
    assert twin3.slave.doStep(5.0, 0.1) == (False, False, False, 5.0 + 0.1)
    assert twin3.get("time") == 5.0 + 0.1
    assert twin3.get("delta_c") == 2.0 * 0.1
    assert twin3.set(time=1.0) == (3, ["c: value reference 0 is not an input or parameter"])


def test_a_failed_step_reports_its_last_successful_time_and_ends_nothing(twin3):
    twin3.initialize()
    twin3.slave.doStep(0.0, 0.1)
    twin3.set(psi=math.inf)
    outputs = [fmi3Boolean(True) for _ in range(3)]
    last = fmi3Float64(-1.0)
    status = twin3.slave._functions["fmi3DoStep"](
        twin3.slave.component, 0.1, 0.1, True, *map(ctypes.byref, outputs), ctypes.byref(last))
    assert (status, [o.value for o in outputs], last.value) == (3, [False] * 3, 0.1)


def test_values_must_be_one_per_value_reference(twin3):
    vr, values = (fmi3ValueReference * 1)(1), (fmi3Float64 * 2)()
    status = twin3.slave._functions["fmi3GetFloat64"](twin3.slave.component, vr, 1, values, 2)
    assert (status, twin3.messages[-1][1]) == (
        3, "c: 2 values for 1 value references (every variable is a scalar)")
    assert twin3.call("getFloat64", [7]) == (
        3, ["c: no Float64 variable has value reference 7"])


def test_what_it_does_not_do_it_refuses_by_name(twin3):
    twin3.initialize()
    assert twin3.call("getFMUState") == (3, ["c: fmi3GetFMUState is not supported by this FMU"])
    assert twin3.call("enterEventMode") == (
        3, ["c: fmi3EnterEventMode is not supported by this FMU"])
    assert twin3.call("getInt32", [1]) == (3, ["c: fmi3GetInt32 is not supported by this FMU"])
    assert twin3.call("getInt32", []) == (0, [])            # no variable of the type: none


def test_it_is_instantiated_only_for_co_simulation_without_event_mode(twins, tmp_path):
    token = read_model_description(str(twins[3])).instantiationToken
    slave = FMU3Slave(guid=token, unzipDirectory=fmpy.extract(str(twins[3]), str(tmp_path)),
                      modelIdentifier=NAME, instanceName="c")
    messages = []

    def log(env, status, category, message):
        messages.append((status, message.decode()))

    with pytest.raises(Exception, match="Failed to instantiate FMU"):
        slave.instantiate(eventModeUsed=True, logMessage=log)
    logger = fmi3LogMessageCallback(log)
    assert not slave._functions["fmi3InstantiateModelExchange"](
        b"c", token.encode(), b"", False, False, fmi3InstanceEnvironment(), logger)
    slave.guid = "{not its token}"
    with pytest.raises(Exception, match="Failed to instantiate FMU"):
        slave.instantiate(logMessage=log)
    assert messages == [(3, "c: this FMU has no event mode (hasEventMode is false)"),
                        (3, "c: this FMU is for co-simulation only, not model exchange")]
    slave.freeLibrary()


BUILD_SOURCES = ("import sys; from fmpy.build import build_platform_binary; "
                 "build_platform_binary(sys.argv[1], all_warnings=True)")
"""A child process's script: build the binary of the unzipped FMU sys.argv[1] from its
sources, with fmpy (CMake), warnings on."""


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmpy_builds_each_twin_from_the_sources_it_carries(twins, tmp_path, fmi):
    if shutil.which("cmake") is None:
        pytest.skip("no cmake, which fmpy builds an FMU's sources with")
    unzipped = Path(fmpy.extract(str(twins[fmi]), str(tmp_path / "fmu")))
    shutil.rmtree(unzipped / "binaries")
    built = subprocess.run([sys.executable, "-I", "-c", BUILD_SOURCES, str(unzipped)],
                           capture_output=True, text=True, timeout=300)
    assert built.returncode == 0, built.stdout + built.stderr
    assert "warning" not in built.stdout.lower()
    rebuilt = shutil.make_archive(str(tmp_path / NAME), "zip", unzipped)
    twin = Twin(Path(shutil.move(rebuilt, tmp_path / f"{NAME}.fmu")), fmi, tmp_path / "again")
    twin.initialize()
    twin.set(psi=0.1, r=0.001)
    assert twin.step(0.0, 0.1) == (0, [])
    assert twin.get("delta_c") == 2.0 * 0.1 + 50.0 * 0.001
    twin.slave.freeInstance()
