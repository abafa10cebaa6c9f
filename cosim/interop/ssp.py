"""A scenario as one .ssp (SystemStructure.ssd, resources/<fmu>.fmu) and an OSP folder beside
it (OspSystemStructure.xml, libcosim's schema 0.1), each whole or not at all."""
from __future__ import annotations

import shutil
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

from fmpy.model_description import ModelDescription

from autopilot_fmu.guidance import ROUTE_PARAMETERS, numeric_route, route

from .. import scenarios
from ..core.files import fresh_folder, whole_file
from ..core.archives import check_archive
from ..core.fmi import read_description
from ..core.ssd import (Component, Connection, SystemDescription, Units, read_ssd, ssv_value,
                        write_ssd)
from ..core.units import unit_of
from ..core.values import fmi_value

SSD_NAME = "SystemStructure.ssd"
FMI2_ONLY = {"libcosim": "OSP libcosim", "fmpy": "fmpy's SSP runner"}   # FMI 2.0 FMUs only
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


def _with_numeric_route(system: SystemDescription, fmus: dict[str, Path]) -> None:
    """A String route as numbers where the FMU declares both: some tools set no String."""
    for name, component in system.components.items():
        if not isinstance(component.parameters.get("waypoints"), str):
            continue
        declared = {v.name for v in read_description(fmus[name], name).modelVariables}
        if declared.issuperset(ROUTE_PARAMETERS):
            route(component.parameters)             # the route as the guidance takes it
            component.parameters.update(numeric_route(component.parameters.pop("waypoints")))


_NEUTRAL = {**dict.fromkeys(("kg", "m", "s", "A", "K", "mol", "cd", "rad"), 0),
            "factor": 1.0, "offset": 0.0}             # a base unit's values left unwritten


def connector_units(system: SystemDescription, fmus: dict[str, Path]) -> Units:
    """Each connector's unit and each unit's definition, from the FMUs' descriptions."""
    connectors: dict[str, dict[str, str]] = {}
    definitions: dict[str, dict[str, float]] = {}
    for name, component in system.components.items():
        described = read_description(fmus[name], name)
        by_name = {v.name: unit_of(v) for v in described.modelVariables}
        connectors[name] = {c: by_name[c] for c in component.connectors if by_name.get(c)}
        for unit in described.unitDefinitions:
            definitions[unit.name] = {k: getattr(unit.baseUnit, k) for k, neutral in
                                      _NEUTRAL.items() if unit.baseUnit and
                                      getattr(unit.baseUnit, k) != neutral}
    for name, by_connector in connectors.items():
        for connector, unit in by_connector.items():
            if unit not in definitions:
                raise ValueError(f"{name}.{connector}: unit {unit!r} has no definition in its "
                                 "FMU's model description")
    return Units(connectors, definitions)


def export(scenario: str | Path, out: Path, overrides: dict[str, dict] | None = None,
           autopilot: str | Path | None = None, port_map: dict[str, str] | None = None,
           name: str | None = None, fmi: int | None = None) -> Path:
    """Write out/<label>.ssp and out/<label>/ (OSP) of ``scenarios.load``'s system."""
    system = scenarios.load(scenario, autopilot, port_map, name, fmi)
    for component, values in system.parameters(overrides).items():
        system.components[component].parameters = values
    fmus = {c: system.fmu_path(c) for c in system.components}     # FileNotFoundError
    by_name: dict[str, Path] = {}
    for component, path in fmus.items():
        check_archive(path)                 # a package we write unpacks where it says
        if by_name.setdefault(path.name, path) != path:
            raise ValueError(f"two FMUs named {path.name} ({by_name[path.name]} and {path}) "
                             "cannot both go into resources/; rename one")
    _with_numeric_route(system, fmus)
    label = scenarios.label(scenario, autopilot, name)
    target = out / f"{label}.ssp"
    with tempfile.TemporaryDirectory() as tmp:
        ssd = Path(tmp) / SSD_NAME
        write_ssd(system, ssd, {c: f"resources/{path.name}" for c, path in fmus.items()},
                  connector_units(system, fmus))
        with whole_file(target) as partial, \
                zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as package:
            package.write(ssd, SSD_NAME)
            for path in sorted(set(fmus.values())):
                package.write(path, f"resources/{path.name}")
    with fresh_folder(out / label) as folder:
        for path in set(fmus.values()):
            shutil.copyfile(path, folder / path.name)
        write_osp(system, folder / OSP_FILE, {c: path.name for c, path in fmus.items()})
    return target


def is_osp(path: Path) -> bool:
    return path.is_dir() or path.suffix.lower() == ".xml"


def described(path: Path) -> tuple[SystemDescription, dict[str, ModelDescription]]:
    """The system of an SSP package or OSP folder or file, and its components' descriptions."""
    with tempfile.TemporaryDirectory() as tmp:
        if is_osp(path):
            system, folder = read_osp(path), path if path.is_dir() else path.parent
        else:
            check_archive(path)             # before it, or another tool, unpacks it
            with zipfile.ZipFile(path) as package:
                package.extractall(tmp)
            system, folder = read_ssd(Path(tmp) / SSD_NAME), Path(tmp)
        for component in system.components.values():      # each FMU another tool unpacks
            check_archive(folder / component.source)
        return system, {name: read_description(folder / component.source, name)
                        for name, component in system.components.items()}


def unapplied_strings(ssp: Path) -> dict[str, tuple[str, str]]:
    """String bindings a tool applying none would drop without a word, not at their FMU's
    default: 'component.variable': (value, default)."""
    system, descriptions = described(ssp)
    dropped = {}
    for name, component in system.components.items():
        starts = {v.name: v.start for v in descriptions[name].modelVariables}
        dropped.update({f"{name}.{v}": (value, starts[v])
                        for v, value in component.parameters.items()
                        if isinstance(value, str) and value != starts[v]})
    return dropped
