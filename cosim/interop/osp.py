"""OSP's OspSystemStructure.xml (libcosim's schema 0.1) beside an SSP package: times, FMUs,
steps, initial values and connections (output first); these systems need no model description."""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from ..core.ssd import Component, Connection, SystemDescription, ssv_value
from ..core.values import fmi_value

OSP_FILE = "OspSystemStructure.xml"
NS = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"


def _q(tag: str) -> str:
    return f"{{{NS}}}{tag}"


def write_osp(system: SystemDescription, path: Path, sources: dict[str, str]) -> None:
    """Write ``system`` at ``path``, ``sources`` each FMU relative to the file's folder."""
    ET.register_namespace("", NS)
    root = ET.Element(_q("OspSystemStructure"), version="0.1")
    for tag, value in (("StartTime", system.start_time), ("EndTime", system.stop_time),
                       ("BaseStepSize", system.step_size)):
        ET.SubElement(root, _q(tag)).text = repr(value)
    ET.SubElement(root, _q("Algorithm")).text = "fixedStep"
    simulators = ET.SubElement(root, _q("Simulators"))
    for name, component in system.components.items():
        simulator = ET.SubElement(simulators, _q("Simulator"), name=name, source=sources[name],
                                  stepSize=repr(system.step_size))
        if component.parameters:
            values = ET.SubElement(simulator, _q("InitialValues"))
            for variable, value in component.parameters.items():
                type_name, text = ssv_value(value)
                initial = ET.SubElement(values, _q("InitialValue"), variable=variable)
                ET.SubElement(initial, _q(type_name), value=text)
    connections = ET.SubElement(root, _q("Connections"))
    for c in system.connections:
        connection = ET.SubElement(connections, _q("VariableConnection"))
        ET.SubElement(connection, _q("Variable"), simulator=c.start_element, name=c.start_connector)
        ET.SubElement(connection, _q("Variable"), simulator=c.end_element, name=c.end_connector)
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


def read_osp(path: Path) -> SystemDescription:
    """The system in an OspSystemStructure.xml (or its folder); ValueError naming it."""
    path = path / OSP_FILE if path.is_dir() else path
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as error:
        raise ValueError(f"cannot read OSP system structure {path}: {error}") from error
    if root.tag != _q("OspSystemStructure"):
        raise ValueError(f"{path} is not an OspSystemStructure")
    components = {}
    for simulator in root.iterfind(f"{_q('Simulators')}/{_q('Simulator')}"):
        name, source = simulator.get("name"), simulator.get("source")
        if not (name and source):
            raise ValueError(f"{path}: a Simulator without name or source")
        component = Component(name=name, source=source)
        for initial in simulator.iterfind(f"{_q('InitialValues')}/{_q('InitialValue')}"):
            (value,) = list(initial)
            component.parameters[initial.get("variable", "")] = fmi_value(
                f"{name}.{initial.get('variable')}", value.tag.rpartition("}")[2],
                value.get("value", ""))
        components[name] = component
    connections = [Connection(start.get("simulator", ""), start.get("name", ""),
                              end.get("simulator", ""), end.get("name", ""))
                   for start, end in root.iterfind(f"{_q('Connections')}/"
                                                   f"{_q('VariableConnection')}")]
    start, stop, step = (fmi_value(f"{path.name} {tag}", "Real", root.findtext(_q(tag), "0.0"))
                         for tag in ("StartTime", "EndTime", "BaseStepSize"))
    return SystemDescription(name=path.parent.name, components=components,
                             connections=connections, start_time=start, stop_time=stop,
                             step_size=step, path=path)
