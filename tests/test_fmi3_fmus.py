"""The FMI 3.0 twins: each validates, declares what its FMI 2.0 twin declares, computes the
same bits from the same inputs, saves and restores its state, and refuses as it should."""
from __future__ import annotations

import importlib
import math
import shutil
import zipfile
from pathlib import Path
from xml.etree.ElementTree import canonicalize, fromstring, tostring

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

from fmubuild.crosscheck import CASES
from fmukit.manifest import read
from fmubuild.project import FMUS
from fmukit.compose import fmu_class

TYPES = {"Float64": "Real", "Int32": "Integer", "String": "String"}
"""An FMI 3.0 type: the FMI 2.0 type of its twin."""
ERROR, FATAL = 3, 4
"""fmi3Error, fmi3Fatal."""


@pytest.mark.parametrize("name", list(FMUS))
def test_each_twin_is_an_fmi3_co_simulation_fmu_that_validates(fmi3_paths, name):
    assert validate_fmu(str(fmi3_paths[name])) == []
    described = read_model_description(str(fmi3_paths[name]))
    assert described.fmiVersion == "3.0" and described.coSimulation is not None
    cs = described.coSimulation
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    assert cs.canHandleVariableCommunicationStepSize
    manifest = read(fmi3_paths[name])
    assert (manifest.fmi, manifest.entry["module"]) == (3, f"{name}_fmi3")


def _declared(fmu: Path) -> dict[str, tuple]:
    """Each variable's declaration as FMI 2.0 names it, but for its value reference."""
    variables = read_model_description(str(fmu)).modelVariables
    return {v.name: (TYPES.get(v.type, v.type), v.causality, v.variability, v.initial, v.unit,
                     v.displayUnit, v.min, v.max, v.start, v.description)
            for v in variables if v.causality != "independent"}


@pytest.mark.parametrize("name", list(FMUS))
def test_each_twin_declares_what_its_fmi2_twin_declares(fmu_paths, fmi3_paths, name):
    two = read_model_description(str(fmu_paths[name]))
    three = read_model_description(str(fmi3_paths[name]))
    assert list(_declared(fmi3_paths[name]).items()) == list(_declared(fmu_paths[name]).items())
    for attribute in ("modelName", "description", "author", "version", "copyright", "license"):
        assert getattr(three, attribute) == getattr(two, attribute), attribute
    experiment = ("startTime", "stopTime", "stepSize", "tolerance")
    assert [getattr(three.defaultExperiment, a) for a in experiment] == \
        [getattr(two.defaultExperiment, a) for a in experiment]

    def units(described):
        return {u.name: (repr(u.baseUnit), [(d.name, d.factor) for d in u.displayUnits])
                for u in described.unitDefinitions}
    assert units(three) == units(two) and units(three)

    def depends(unknowns):
        return [(u.variable.name, [d.name for d in u.dependencies]) for u in unknowns]
    assert depends(three.outputs) == depends(two.outputs)
    assert depends(three.initialUnknowns) == depends(two.initialUnknowns)


@pytest.mark.parametrize("name", list(FMUS))
def test_time_is_value_reference_0_written_last_and_every_other_is_its_twins_plus_one(
        fmu_paths, fmi3_paths, name):
    """OMSimulator reads FMI 3.0 dependencies as 1-based positions: each value reference
    must be its variable's position."""
    three = read_model_description(str(fmi3_paths[name])).modelVariables
    independent = [v for v in three if v.causality == "independent"]
    assert [(v.name, v.valueReference, v.start) for v in independent] == [("time", 0, None)]
    assert three[-1] is independent[0]
    assert [v.valueReference for v in three[:-1]] == list(range(1, len(three)))
    two = {v.name: v.valueReference for v in read_model_description(
        str(fmu_paths[name])).modelVariables}
    assert {v.name: v.valueReference - 1 for v in three[:-1]} == two


def _signal(name: str) -> tuple[np.ndarray, float]:
    """The cross-check case's inputs of FMU ``name`` as fmpy's input signal, and its stop."""
    case = CASES[name]
    signal = np.array([tuple(map(float, row)) for row in case.table],
                      dtype=[("time", float)] + [(i, float) for i in case.inputs])
    return signal, case.stop


@pytest.mark.parametrize("name", list(FMUS))
def test_each_twin_gives_its_fmi2_twins_outputs_bit_for_bit(fmu_paths, fmi3_paths, name):
    signal, stop = _signal(name)
    results = [simulate_fmu(str(paths[name]), stop_time=stop, step_size=CASES[name].step,
                            input=signal, output_interval=CASES[name].step)
               for paths in (fmu_paths, fmi3_paths)]
    two, three = results
    assert two.dtype.names == three.dtype.names and len(two) == len(three) > 100
    for column in two.dtype.names:
        assert two[column].tobytes() == three[column].tobytes(), column
    assert not np.isnan(two[two.dtype.names[1]]).any()         # a run, not a failed one


class Twin:
    """An FMI 3.0 twin opened with fmpy, with the messages it sends the host."""

    def __init__(self, fmu: Path, instance_name: str, logging: bool = True):
        self.described = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in self.described.modelVariables}
        self.folder = extract(str(fmu))
        self.heard: list[tuple[int, str, str]] = []
        self.slave = FMU3Slave(guid=self.described.guid, unzipDirectory=self.folder,
                               modelIdentifier=self.described.coSimulation.modelIdentifier,
                               instanceName=instance_name)
        self.slave.instantiate(loggingOn=logging, logMessage=self._log)

    def _log(self, environment, status, category, message) -> None:
        self.heard.append((status, category.decode(), message.decode()))

    def initialize(self) -> None:
        self.slave.enterInitializationMode(startTime=0.0)
        self.slave.exitInitializationMode()

    def get(self, *names: str) -> list[float]:
        return self.slave.getFloat64([self.vr[n] for n in names])

    def set(self, **values: float) -> None:
        self.slave.setFloat64([self.vr[n] for n in values], list(values.values()))

    def status(self, call, *args) -> int:
        """The status of a call: 0, or the failed status it raised."""
        try:
            call(*args)
            return 0
        except FMICallException as failed:
            return failed.status

    def free(self) -> None:
        self.slave.freeInstance()
        shutil.rmtree(self.folder, ignore_errors=True)


@pytest.fixture
def twin(fmi3_paths):
    opened = []

    def open_(name: str, instance_name: str | None = None, logging: bool = True) -> Twin:
        opened.append(Twin(fmi3_paths[name], instance_name or name, logging))
        return opened[-1]
    yield open_
    for one in opened:
        one.free()


SHIP_STATES = ("x", "y", "psi", "u", "v", "r", "delta")


def test_the_ships_state_is_restored_and_deserialised_bit_for_bit(twin):
    ship = twin("ship")
    ship.initialize()
    ship.set(delta_c=0.3, n1=8.13, n2=8.13)
    for k in range(50):
        ship.slave.doStep(k * 0.1, 0.1)
    saved, time = ship.slave.getFMUState(), ship.get("time")
    serialized = ship.slave.serializeFMUState(saved)
    ship.set(delta_c=-0.2)
    ahead = []
    for k in range(50, 100):
        ship.slave.doStep(k * 0.1, 0.1)
        ahead.append(ship.get(*SHIP_STATES, "time"))
    for restore in (lambda: ship.slave.setFMUState(saved),
                    lambda: ship.slave.setFMUState(ship.slave.deserializeFMUState(serialized))):
        restore()
        assert ship.get("time") == time
        ship.set(delta_c=-0.2)
        again = []
        for k in range(50, 100):
            ship.slave.doStep(k * 0.1, 0.1)
            again.append(ship.get(*SHIP_STATES, "time"))
        assert np.array(again).tobytes() == np.array(ahead).tobytes()
    ship.slave.freeFMUState(saved)


def test_a_refused_step_is_an_error_naming_the_input_and_reset_revives_the_twin(twin):
    pd = twin("pd_autopilot", "pd")
    pd.initialize()
    pd.set(psi=math.nan)
    assert pd.status(pd.slave.doStep, 0.0, 0.1) == ERROR            # not fatal
    assert math.isnan(pd.get("delta_c")[0])
    pd.set(psi=0.1)
    assert pd.status(pd.slave.doStep, 0.0, 0.1) == ERROR            # failed until reset
    assert [(s, c) for s, c, _ in pd.heard] == [(ERROR, "fmukit.nonfinite_input")] * 2
    assert pd.heard[0][2] == ("pd: doStep at t = 0.0: input psi = nan is not finite; the FMU "
                              "has failed (its outputs read NaN until fmi3Reset)")
    pd.slave.reset()
    pd.initialize()
    pd.set(psi=0.1)
    pd.slave.doStep(0.0, 0.1)
    assert pd.get("delta_c") == [0.2]


def test_a_bad_parameter_is_named_at_initialisation_and_refuses_the_first_step(twin):
    pd = twin("pd_autopilot", "pd")
    pd.set(Kp=math.inf)
    pd.initialize()                                   # OSP libcosim ends its host otherwise
    assert pd.heard == [(ERROR, "fmukit.parameter", ("pd: exitInitializationMode: parameter "
                                                    "Kp = inf is not finite; the FMU has "
                                                    "failed"))]
    assert pd.status(pd.slave.doStep, 0.0, 0.1) == ERROR


def test_calls_fmi3_allows_no_error_for_are_fatal_and_named(twin):
    pd = twin("pd_autopilot", "pd")
    assert pd.status(pd.slave.doStep, 0.0, 0.1) == ERROR              # out of sequence
    assert "doStep called in phase 'instantiated'" in pd.heard[-1][2]
    pd.initialize()
    assert pd.status(pd.slave.setFloat64, [pd.vr["delta_c"]], [1.0]) == FATAL
    assert ("pd: delta_c is an output and cannot be set" in [m for _, _, m in pd.heard])
    assert pd.status(pd.slave.setFloat64, [pd.vr["Kp"]], [1.0]) == FATAL
    assert any("parameter Kp is fixed after initialisation" in m for _, _, m in pd.heard)
    assert pd.status(pd.slave.enterInitializationMode) == FATAL
    assert any("fmi3EnterInitializationMode is not allowed in phase 'step' (FMI 3.0 allows it "
               "after fmi3InstantiateCoSimulation or fmi3Reset)" in m for _, _, m in pd.heard)


def test_with_logging_off_the_host_hears_nothing_and_standard_error_says_why_once(twin,
                                                                                 capfd):
    pd = twin("pd_autopilot", "pd", logging=False)
    pd.initialize()
    pd.set(psi=math.nan)
    for _ in range(2):
        assert pd.status(pd.slave.doStep, 0.0, 0.1) == ERROR
    assert pd.heard == []
    assert capfd.readouterr().err == ("pd: doStep at t = 0.0: input psi = nan is not finite; "
                                      "the FMU has failed (its outputs read NaN until "
                                      "fmi3Reset)\n")
    pd.slave.setDebugLogging(True, [])                 # the host's flag, read each time
    assert pd.status(pd.slave.doStep, 0.0, 0.1) == ERROR
    assert len(pd.heard) == 1 and capfd.readouterr().err == ""


def test_with_logging_on_errors_go_to_the_host_only(twin, capfd):
    pd = twin("pd_autopilot", "pd")
    pd.initialize()
    pd.set(psi=math.nan)
    pd.status(pd.slave.doStep, 0.0, 0.1)
    assert len(pd.heard) == 1 and capfd.readouterr().err == ""


def test_fmi2_and_fmi3_twins_run_side_by_side_in_one_process(fmu_paths, twin, open_fmu):
    """They share the modules of one interpreter: the same sources, imported once."""
    three = twin("pd_autopilot", "pd3")
    two = open_fmu("pd_autopilot", "pd2")
    three.initialize()
    two.initialize()
    for k, psi in enumerate((0.1, -0.3, 0.25)):
        three.set(psi=psi, r=0.01)
        two.set({"psi": psi, "r": 0.01})
        three.slave.doStep(k * 0.1, 0.1)
        two.do_step(k * 0.1, 0.1)
        assert three.get("delta_c") == [two.get(["delta_c"])["delta_c"]]


@pytest.mark.parametrize("name", list(FMUS))
def test_the_class_composed_in_code_declares_what_each_fmu_does(fmu_paths, fmi3_paths, name):
    """fmukit.compose.fmu_class, which the in-process backend runs: the same declarations as
    the FMU's own class, FMI 3.0's value references FMI 2.0's plus one."""
    manifest = read(fmu_paths[name])
    model = getattr(importlib.import_module(manifest.slave_module), manifest.slave_class)
    registries = {}
    for fmi, paths in ((2, fmu_paths), (3, fmi3_paths)):
        slave = fmu_class(model, fmi)(instance_name=name)
        assert slave.FMI_VERSION == fmi and fmu_class(model, fmi) is type(slave)
        with zipfile.ZipFile(paths[name]) as fmu:
            built = fromstring(fmu.read("modelDescription.xml"))
        for section in ("ModelVariables", "UnitDefinitions", "ModelStructure"):
            assert canonicalize(tostring(slave.to_xml().find(section)), strip_text=True) == \
                canonicalize(tostring(built.find(section)), strip_text=True), (fmi, section)
        registries[fmi] = {var.name: vr for vr, var in slave.registry.by_vr.items()}
    assert {n: vr + 1 for n, vr in registries[2].items()} == registries[3]
    with pytest.raises(ValueError, match="FMI 1 is not one fmukit builds"):
        fmu_class(model, 1)
