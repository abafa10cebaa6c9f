"""Read and write SSP 1.0 system structure descriptions (.ssd) of a flat system.

The subset used here is the one OSP libcosim, ecos and fmpy all read: one system of
FMU components with connectors, inline parameter sets (ssv:Real, Integer, Boolean,
String), connections, and a DefaultExperiment whose OSP annotation gives the fixed
step. This project adds one annotation of its own (type ``REPORT_ANNOTATION``)
naming the kind of analysis a run of the system gets (``cosim.analysis.kinds``);
other tools ignore it.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fmubuild.project import FMU_DIR, FMUS

from .errors import FmuNotFound

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "sap": "https://github.com/ship-autopilot-cosim/annotations",
}
OSP_ANNOTATION = "com.opensimulationplatform"
REPORT_ANNOTATION = "org.ship-autopilot-cosim"
PARAMETER_SET = "scenario"
_TYPES = {"Real": float, "Integer": int, "Boolean": lambda s: s.strip().lower() in ("true", "1"),
          "String": str}

FMU_SEARCH_PATH = [FMU_DIR]
"""Folders searched, by file name, for an FMU not found where its .ssd points: the
project's fmus/, so that a scenario copied anywhere still finds the project's FMUs."""

for _prefix, _uri in NS.items():
    ET.register_namespace(_prefix, _uri)



def split_name(name: str) -> tuple[str, str]:
    """'ship.psi' -> ('ship', 'psi'): a variable by its component; ValueError naming ``name``
    if it is not of the form component.variable."""
    component, dot, variable = name.partition(".")
    if not (dot and component and variable):
        raise ValueError(f"{name!r} is not 'component.variable'")
    return component, variable

@dataclass
class Component:
    name: str
    source: str                                  # FMU path, relative to the .ssd
    connectors: dict[str, tuple[str, str]] = field(default_factory=dict)   # name: (kind, type)
    parameters: dict[str, float | int | bool | str] = field(default_factory=dict)


@dataclass(frozen=True)
class Connection:
    start_element: str
    start_connector: str
    end_element: str
    end_connector: str

    def __str__(self) -> str:
        return (f"{self.start_element}.{self.start_connector} -> "
                f"{self.end_element}.{self.end_connector}")


@dataclass
class SystemDescription:
    name: str
    components: dict[str, Component]
    connections: list[Connection]
    start_time: float = 0.0
    stop_time: float = 400.0
    step_size: float = 0.1
    report: str = "none"
    description: str = ""
    path: Path | None = None                     # the .ssd this was read from

    def parameters(self, overrides: dict[str, dict[str, Any]] | None = None
                   ) -> dict[str, dict[str, Any]]:
        """Each component's parameter values, updated by ``overrides`` (by component);
        ValueError naming a component the system does not have."""
        parameters = {name: dict(c.parameters) for name, c in self.components.items()}
        for component, values in (overrides or {}).items():
            if component not in parameters:
                raise ValueError(f"--set names the component '{component}'; the system has "
                                 f"{', '.join(parameters)}")
            parameters[component].update(values)
        return parameters

    def fmu_candidates(self, component: str) -> list[Path]:
        """Where a component's FMU may be: its source relative to the .ssd (or the current
        folder), then a file of that name in each of ``FMU_SEARCH_PATH``."""
        source = Path(self.components[component].source)
        base = self.path.parent if self.path else Path.cwd()
        candidates = [(base / source).resolve(), *(d / source.name for d in FMU_SEARCH_PATH)]
        return list(dict.fromkeys(candidates))

    def fmu_path(self, component: str) -> Path:
        """The first of ``fmu_candidates`` that exists; FileNotFoundError naming all tried."""
        candidates = self.fmu_candidates(component)
        for path in candidates:
            if path.is_file():
                return path
        source = Path(self.components[component].source)
        ours = source.stem in FMUS
        hint = ("one of this project's FMUs, not built" if ours
                else f"check the source of component '{component}' in {self.path or 'the system'}")
        raise FmuNotFound(f"FMU for '{component}' not found; tried "
                          f"{', '.join(map(str, candidates))}; {hint}", ours)


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _type_of(element: ET.Element, prefix: str) -> tuple[str, ET.Element]:
    for name in _TYPES:
        child = element.find(f"{prefix}:{name}", NS)
        if child is not None:
            return name, child
    raise ValueError(f"{element.get('name')!r} has no Real, Integer, Boolean or String type")


def read_ssd(path: str | Path) -> SystemDescription:
    """Parse a .ssd file; ValueError naming the file and the problem if it is not one."""
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as error:
        raise ValueError(f"cannot read system structure {path}: {error}") from error
    if root.tag != _q("ssd", "SystemStructureDescription"):
        raise ValueError(f"{path} is not an SSP system structure description")
    system = root.find("ssd:System", NS)
    components = {}
    for c in system.findall("ssd:Elements/ssd:Component", NS):
        component = Component(name=c.get("name"), source=c.get("source"))
        for connector in c.findall("ssd:Connectors/ssd:Connector", NS):
            kind_type = _type_of(connector, "ssc")[0]
            component.connectors[connector.get("name")] = (connector.get("kind"), kind_type)
        for p in c.findall("ssd:ParameterBindings/ssd:ParameterBinding/ssd:ParameterValues/"
                           "ssv:ParameterSet/ssv:Parameters/ssv:Parameter", NS):
            type_name, value = _type_of(p, "ssv")
            component.parameters[p.get("name")] = _TYPES[type_name](value.get("value"))
        components[component.name] = component
    connections = [Connection(c.get("startElement"), c.get("startConnector"),
                              c.get("endElement"), c.get("endConnector"))
                   for c in system.findall("ssd:Connections/ssd:Connection", NS)]
    description = SystemDescription(name=root.get("name"), components=components,
                                    connections=connections,
                                    description=system.get("description", ""), path=path)
    experiment = root.find("ssd:DefaultExperiment", NS)
    if experiment is not None:
        description.start_time = float(experiment.get("startTime", 0.0))
        description.stop_time = float(experiment.get("stopTime", description.stop_time))
        algorithm = experiment.find("ssd:Annotations/ssc:Annotation/osp:Algorithm/"
                                    "osp:FixedStepAlgorithm", NS)
        if algorithm is not None:
            description.step_size = float(algorithm.get("baseStepSize"))
        report = experiment.find("ssd:Annotations/ssc:Annotation/sap:Report", NS)
        if report is not None:
            description.report = report.get("kind")
    for connection in connections:
        for element in (connection.start_element, connection.end_element):
            if element not in components:
                raise ValueError(f"{path}: connection {connection} names the component "
                                 f"'{element}', which the system does not have")
    return description


def _format(value: float | int | bool | str) -> tuple[str, str]:
    if isinstance(value, bool):
        return "Boolean", str(value).lower()
    if isinstance(value, int):
        return "Integer", str(value)
    if isinstance(value, float):
        return "Real", repr(value)
    return "String", value


def write_ssd(system: SystemDescription, path: str | Path,
              sources: dict[str, str] | None = None) -> None:
    """Write ``system`` as a .ssd; ``sources`` replaces component sources by name."""
    root = ET.Element(_q("ssd", "SystemStructureDescription"), version="1.0", name=system.name)
    sys_el = ET.SubElement(root, _q("ssd", "System"), name=system.name,
                           description=system.description)
    elements = ET.SubElement(sys_el, _q("ssd", "Elements"))
    for c in system.components.values():
        source = (sources or {}).get(c.name, c.source)
        comp = ET.SubElement(elements, _q("ssd", "Component"), name=c.name, source=source,
                             type="application/x-fmu-sharedlibrary")
        connectors = ET.SubElement(comp, _q("ssd", "Connectors"))
        for name, (kind, type_name) in c.connectors.items():
            connector = ET.SubElement(connectors, _q("ssd", "Connector"), name=name, kind=kind)
            ET.SubElement(connector, _q("ssc", type_name))
        if c.parameters:
            binding = ET.SubElement(ET.SubElement(comp, _q("ssd", "ParameterBindings")),
                                    _q("ssd", "ParameterBinding"))
            values = ET.SubElement(binding, _q("ssd", "ParameterValues"))
            pset = ET.SubElement(values, _q("ssv", "ParameterSet"), version="1.0",
                                 name=PARAMETER_SET)
            params = ET.SubElement(pset, _q("ssv", "Parameters"))
            for name, value in c.parameters.items():
                type_name, text = _format(value)
                p = ET.SubElement(params, _q("ssv", "Parameter"), name=name)
                ET.SubElement(p, _q("ssv", type_name), value=text)
    connections = ET.SubElement(sys_el, _q("ssd", "Connections"))
    for k in system.connections:
        ET.SubElement(connections, _q("ssd", "Connection"), startElement=k.start_element,
                      startConnector=k.start_connector, endElement=k.end_element,
                      endConnector=k.end_connector)
    experiment = ET.SubElement(root, _q("ssd", "DefaultExperiment"),
                               startTime=repr(system.start_time), stopTime=repr(system.stop_time))
    annotations = ET.SubElement(experiment, _q("ssd", "Annotations"))
    osp = ET.SubElement(annotations, _q("ssc", "Annotation"), type=OSP_ANNOTATION)
    ET.SubElement(ET.SubElement(osp, _q("osp", "Algorithm")), _q("osp", "FixedStepAlgorithm"),
                  baseStepSize=repr(system.step_size))
    ours = ET.SubElement(annotations, _q("ssc", "Annotation"), type=REPORT_ANNOTATION)
    ET.SubElement(ours, _q("sap", "Report"), kind=system.report)
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)
