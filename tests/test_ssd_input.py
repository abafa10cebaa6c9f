"""Malformed .ssd files are refused with one message naming the file, the element and the
attribute (issue 25), never a traceback."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from cosim import run as run_command
from cosim.core.ssd import read_ssd, write_ssd
from helpers import command

ROOT = Path(__file__).resolve().parent.parent

GOOD = """<?xml version='1.0' encoding='UTF-8'?>
<ssd:SystemStructureDescription xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations"
    xmlns:sap="https://github.com/ship-autopilot-cosim/annotations"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    version="1.0" name="tiny">
  <ssd:System name="tiny" description="two components">
    <ssd:Elements>
      <ssd:Component name="autopilot" source="pd_autopilot.fmu"
          type="application/x-fmu-sharedlibrary">
        <ssd:Connectors>
          <ssd:Connector name="psi" kind="input"><ssc:Real /></ssd:Connector>
          <ssd:Connector name="delta_c" kind="output"><ssc:Real /></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="scenario">
                <ssv:Parameters>
                  <ssv:Parameter name="Kp"><ssv:Real value="2.0" /></ssv:Parameter>
                  <ssv:Parameter name="seed"><ssv:Integer value="7" /></ssv:Parameter>
                  <ssv:Parameter name="flag"><ssv:Boolean value="false" /></ssv:Parameter>
                  <ssv:Parameter name="route"><ssv:String value="0,0;1,1" /></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="ship" source="ship.fmu">
        <ssd:Connectors>
          <ssd:Connector name="delta_c" kind="input"><ssc:Real /></ssd:Connector>
          <ssd:Connector name="psi" kind="output"><ssc:Real /></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="ship" startConnector="psi" endElement="autopilot"
          endConnector="psi" />
      <ssd:Connection startElement="autopilot" startConnector="delta_c" endElement="ship"
          endConnector="delta_c" />
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0.0" stopTime="400.0">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="0.1" /></osp:Algorithm>
      </ssc:Annotation>
      <ssc:Annotation type="org.ship-autopilot-cosim">
        <sap:Report kind="course_keeping" />
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""

SHIP = '<ssd:Component name="ship" source="ship.fmu">'
KP = '<ssv:Real value="2.0" />'
FIRST_CONNECTION = ('<ssd:Connection startElement="ship" startConnector="psi" '
                    'endElement="autopilot"\n          endConnector="psi" />')
PARAMETERS_END = "</ssv:Parameters>"


def _component(name: str = "ship", source: str = "x.fmu", extra: str = "") -> str:
    return f'<ssd:Component name="{name}" source="{source}"{extra}></ssd:Component>\n'


MALFORMED = [   # (what, old text, new text, the message's element and problem)
    ("no System", (GOOD[GOOD.index("  <ssd:System "):GOOD.index("  <ssd:DefaultExperiment")]),
     "", "SystemStructureDescription: needs one System element, has 0"),
    ("two Systems", "  <ssd:DefaultExperiment",
     '  <ssd:System name="b" />\n  <ssd:DefaultExperiment',
     "needs one System element, has 2"),
    ("no root name", 'version="1.0" name="tiny"', 'version="1.0"',
     "SystemStructureDescription: no name attribute"),
    ("no Elements", GOOD[GOOD.index("    <ssd:Elements>"):GOOD.index("    <ssd:Connections>")],
     "", "System: no Component in its Elements"),
    ("component without name", SHIP, '<ssd:Component source="ship.fmu">',
     "Component 2: no name attribute"),
    ("component with an empty name", SHIP, '<ssd:Component name=" " source="ship.fmu">',
     "Component 2: an empty name attribute"),
    ("component without source", SHIP, '<ssd:Component name="ship">',
     "Component 'ship': no source attribute"),
    ("two components of one name", SHIP, _component("autopilot") + "      " + SHIP,
     "Component 2: a second Component named 'autopilot'"),
    ("a dot in a component name", SHIP, '<ssd:Component name="my.ship" source="ship.fmu">',
     "Component 'my.ship': a '.' in its name"),
    ("a component that is not an FMU", SHIP,
     '<ssd:Component name="ship" source="s.ssp" type="application/x-ssp-package">',
     "Component 'ship': type 'application/x-ssp-package' is not read"),
    ("a nested system", SHIP, '<ssd:System name="inner" />\n      ' + SHIP,
     "System, element 2 of Elements: ssd:System is not read"),
    ("connector without name", '<ssd:Connector name="psi" kind="input">',
     '<ssd:Connector kind="input">', "Component 'autopilot', Connector 1: no name attribute"),
    ("connector without kind", '<ssd:Connector name="psi" kind="input">',
     '<ssd:Connector name="psi">', "Component 'autopilot', Connector 'psi': no kind attribute"),
    ("connector of an unknown kind", '<ssd:Connector name="psi" kind="input">',
     '<ssd:Connector name="psi" kind="sideways">', "kind 'sideways' is not one of input"),
    ("connector without type", '<ssd:Connector name="psi" kind="input"><ssc:Real />',
     '<ssd:Connector name="psi" kind="input">',
     "Connector 'psi': needs one of ssc:Real, ssc:Integer, ssc:Boolean, ssc:String "
     "(found: none)"),
    ("connector declared twice", '<ssd:Connector name="delta_c" kind="output">',
     '<ssd:Connector name="psi" kind="output">', "Connector 'psi': declared twice"),
    ("parameter without name", '<ssv:Parameter name="Kp">', "<ssv:Parameter>",
     "Component 'autopilot', ParameterBinding, Parameter 1: no name attribute"),
    ("parameter without value", KP, "<ssv:Real />",
     "Component 'autopilot', Parameter 'Kp', ssv:Real: no value attribute"),
    ("parameter with an empty value", KP, '<ssv:Real value="" />',
     "Parameter 'Kp', ssv:Real: an empty value attribute"),
    ("parameter without type", KP, "", "Parameter 'Kp': needs one of ssv:Real"),
    ("parameter of an unknown type", KP, '<ssv:Enumeration value="fast" />',
     "Parameter 'Kp': needs one of ssv:Real, ssv:Integer, ssv:Boolean, ssv:String "
     "(found: ssv:Enumeration)"),
    ("parameter of two types", KP, KP + '<ssv:Integer value="2" />',
     "(found: ssv:Real, ssv:Integer)"),
    ("a Real that is not a number", KP, '<ssv:Real value="two" />',
     "Parameter 'Kp', ssv:Real: autopilot.Kp = 'two' is not a number"),
    ("a Real in hexadecimal", KP, '<ssv:Real value="0x10" />', "'0x10' is not a number"),
    ("a Real beyond a double", KP, '<ssv:Real value="1e999" />',
     "'1e999' is beyond the range of a double"),
    ("an Integer with a fraction", '<ssv:Integer value="7" />', '<ssv:Integer value="1.5" />',
     "Parameter 'seed', ssv:Integer: autopilot.seed = '1.5' is not a whole number"),
    ("an Integer beyond 32 bits", '<ssv:Integer value="7" />',
     '<ssv:Integer value="4294967297" />', "is outside the range of an FMI Integer (32 bits)"),
    ("a Boolean that is not one", '<ssv:Boolean value="false" />',
     '<ssv:Boolean value="fals" />', "autopilot.flag = 'fals' is not a Boolean"),
    ("a Real with a unit", KP, '<ssv:Real value="2.0" unit="deg" />',
     "Parameter 'Kp', ssv:Real: unit='deg' is not read"),
    ("a parameter given twice", PARAMETERS_END,
     '<ssv:Parameter name="Kp"><ssv:Real value="3.0" /></ssv:Parameter>' + PARAMETERS_END,
     "Component 'autopilot', Parameter 'Kp': given twice"),
    ("parameter values in an .ssv file", "<ssd:ParameterBinding>",
     '<ssd:ParameterBinding source="values.ssv">',
     "ParameterBinding: source='values.ssv': parameter values in another file is not read"),
    ("a binding without values", "<ssd:ParameterBinding>",
     "<ssd:ParameterBinding /><ssd:ParameterBinding>",
     "Component 'autopilot', ParameterBinding: no ParameterValues"),
    ("a connection to an unknown component", 'endElement="ship"', 'endElement="boat"',
     "Connection 2 (autopilot.delta_c -> boat.delta_c): names the component 'boat', which "
     "the system does not have; it has autopilot, ship"),
    ("a connection without endConnector", 'endElement="ship"\n          endConnector="delta_c"',
     'endElement="ship"', "Connection 2: no endConnector attribute"),
    ("a connection from the system itself", FIRST_CONNECTION,
     '<ssd:Connection startConnector="psi" endElement="autopilot" endConnector="psi" />',
     "Connection 1: no startElement attribute (connectors of the system itself are not read)"),
    ("an input fed twice", FIRST_CONNECTION, FIRST_CONNECTION + FIRST_CONNECTION,
     "Connection 2 (ship.psi -> autopilot.psi): autopilot.psi is fed already by Connection 1"),
    ("a start time that is not a number", 'startTime="0.0"', 'startTime="zero"',
     "DefaultExperiment: startTime='zero' is not a finite number"),
    ("a stop time of NaN", 'stopTime="400.0"', 'stopTime="NaN"',
     "DefaultExperiment: stopTime='NaN' is not a finite number"),
    ("a stop time before the start", 'stopTime="400.0"', 'stopTime="-1"',
     "DefaultExperiment: stop time -1.0 s is not after the start time 0.0 s"),
    ("no step size", ' baseStepSize="0.1"', "",
     "DefaultExperiment, osp:FixedStepAlgorithm: no baseStepSize attribute"),
    ("a step of 0", 'baseStepSize="0.1"', 'baseStepSize="0"',
     "DefaultExperiment: step size 0.0 s is not positive (at least 1 ns)"),
    ("a step that is not a number", 'baseStepSize="0.1"', 'baseStepSize="0,1"',
     "baseStepSize='0,1' is not a finite number"),
    ("a step off the time base", 'baseStepSize="0.1"', 'baseStepSize="0.10000000001"',
     "DefaultExperiment: baseStepSize 0.10000000001 s is not a whole number of nanoseconds"),
    ("a step below a nanosecond", 'baseStepSize="0.1"', 'baseStepSize="1e-12"',
     "DefaultExperiment: step size 1e-12 s is not positive (at least 1 ns)"),
    ("a stop time between two steps", 'stopTime="400.0"', 'stopTime="400.05"',
     "DefaultExperiment: stop time 400.05 s is not a whole number of 0.1 s steps after 0.0 s"),
    ("a report without a kind", '<sap:Report kind="course_keeping" />', "<sap:Report />",
     "DefaultExperiment, sap:Report: no kind attribute"),
]


def _write(tmp_path: Path, text: str, name: str = "bad.ssd") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_good_file_reads_as_written(tmp_path):
    system = read_ssd(_write(tmp_path, GOOD))
    assert system.components["autopilot"].parameters == {"Kp": 2.0, "seed": 7, "flag": False,
                                                         "route": "0,0;1,1"}
    assert [str(c) for c in system.connections] == ["ship.psi -> autopilot.psi",
                                                     "autopilot.delta_c -> ship.delta_c"]
    assert (system.start_time, system.stop_time, system.step_size, system.report) == \
        (0.0, 400.0, 0.1, "course_keeping")


@pytest.mark.parametrize("old, new, fragment", [case[1:] for case in MALFORMED],
                         ids=[case[0] for case in MALFORMED])
def test_a_malformed_ssd_is_refused_naming_the_file_and_the_element(tmp_path, old, new,
                                                                     fragment):
    assert old in GOOD
    path = _write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(ValueError) as refused:
        read_ssd(path)
    message = str(refused.value)
    assert message.startswith(f"{path}: ") and fragment in message, message


@pytest.mark.parametrize("text, fragment", [
    ("", "cannot read system structure"),
    ("<ssd:System", "cannot read system structure"),
    ("<fmiModelDescription />", "is not an SSP system structure description (its root "
                                "element is fmiModelDescription)"),
])
def test_what_is_not_an_ssd_is_refused_naming_the_file(tmp_path, text, fragment):
    path = _write(tmp_path, text)
    with pytest.raises(ValueError) as refused:
        read_ssd(path)
    assert str(path) in str(refused.value) and fragment in str(refused.value)


def test_a_boolean_binding_reads_as_its_text_says(tmp_path):
    for text, value in (("false", False), ("FALSE", False), ("0", False), (" true ", True),
                        ("1", True)):
        path = _write(tmp_path, GOOD.replace('<ssv:Boolean value="false" />',
                                             f'<ssv:Boolean value="{text}" />'))
        assert read_ssd(path).components["autopilot"].parameters["flag"] is value


def test_what_write_ssd_writes_read_ssd_reads_back(tmp_path):
    system = read_ssd(_write(tmp_path, GOOD, "good.ssd"))
    write_ssd(system, tmp_path / "again.ssd")
    again = read_ssd(tmp_path / "again.ssd")
    assert again.components == system.components and again.connections == system.connections


@pytest.mark.parametrize("case", ["no System", "parameter without value",
                                  "a connection to an unknown component"])
def test_the_command_line_refuses_a_malformed_ssd_in_one_line(tmp_path, case):
    _, old, new, fragment = next(c for c in MALFORMED if c[0] == case)
    path = _write(tmp_path, GOOD.replace(old, new, 1))
    child = command(run_command.main, str(path), "--out", str(tmp_path / "out"), "--no-plot")
    assert child.returncode == 2, child.stderr
    assert "Traceback" not in child.stderr
    assert child.stderr.startswith(f"error: {path}: ") and fragment in child.stderr
    assert child.stderr.count("error:") == 1, child.stderr


def test_names_that_no_file_takes_as_they_are_are_refused_up_front(tmp_path):
    """Issue 38: a component named 'auto,pilot' gave a CSV whose header had more fields than
    its rows, every column after it mislabelled, exit 0."""
    from cosim.core.ssd import Component, SystemDescription, read_ssd, write_ssd

    for bad in ("auto,pilot", "1st", "a b", "pilot\n", "é", ""):
        with pytest.raises(ValueError, match=f"component name {re.escape(repr(bad))}: a "
                                             "component is named with ASCII letters"):
            SystemDescription("s", {bad: Component(bad, "x.fmu")}, [])
    with pytest.raises(ValueError, match="pilot.psi,d: a connector's name holds no comma"):
        SystemDescription("s", {"pilot": Component("pilot", "x.fmu",
                                                   {"psi,d": ("input", "Real")})}, [])
    SystemDescription("s", {"auto_pilot2": Component("auto_pilot2", "x.fmu",
                                                     {"der(x)[1].y": ("output", "Real")})}, [])
    ssd = tmp_path / "bad.ssd"
    write_ssd(SystemDescription("s", {"pilot": Component("pilot", "x.fmu")}, []), ssd)
    ssd.write_text(ssd.read_text().replace('name="pilot"', 'name="auto,pilot"'))
    with pytest.raises(ValueError, match=f"{re.escape(str(ssd))}: System: component name "
                                         "'auto,pilot'"):
        read_ssd(ssd)


def test_an_export_names_its_system_as_every_tool_takes_an_identifier(fmu_paths, tmp_path):
    """Issue 38: every `cosim.export --autopilot` package aborted OMSimulator's command line
    ('"calm_pd-..." is not a valid ident')."""
    import shutil
    import xml.etree.ElementTree as ET
    import zipfile

    from cosim.interop.ssp import export

    mine = tmp_path / "my-pid 2.fmu"
    shutil.copy(fmu_paths["pd_autopilot"], mine)
    (tmp_path / "out").mkdir()
    package = export("calm_pd", tmp_path / "out", autopilot=mine)
    with zipfile.ZipFile(package) as ssp:
        root = ET.fromstring(ssp.read("SystemStructure.ssd"))
    names = {root.get("name"), root.find("{*}System").get("name")}
    assert names == {"calm_pd_my_pid_2"}
