"""Read and write SSP 1.0 system structure descriptions (.ssd) of a flat system: the subset OSP
libcosim, ecos and fmpy all read (FMU components, connectors, inline parameter values,
connections, the step in OSP's annotation); ``read_ssd`` refuses anything else by name."""
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from fmukit.timebase import on_time_base, step_count

from .system import Component, Connection, FmuFolders, SystemDescription
from .values import fmi_value

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "sap": "https://github.com/ship-autopilot-cosim/annotations",
    "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
}
_TYPES = ("Real", "Integer", "Boolean", "String")
FMU_TYPE = "application/x-fmu-sharedlibrary"
CONNECTOR_KINDS = ("input", "output", "inout", "parameter", "calculatedParameter")

for _prefix, _uri in NS.items():
    ET.register_namespace(_prefix, _uri)


def _q(prefixed: str) -> str:                   # 'ssd:System' as ElementTree names it
    prefix, _, tag = prefixed.partition(":")
    return f"{{{NS[prefix]}}}{tag}"


def _local(element: ET.Element) -> str:         # its tag as the file writes it: 'ssv:Real'
    uri, _, tag = element.tag.rpartition("}")
    prefix = next((p for p, u in NS.items() if f"{{{u}" == uri), None)
    return f"{prefix}:{tag}" if prefix else tag


@dataclass
class _Reader:
    """Reads one .ssd; every error names the file, the element and the attribute."""
    path: Path

    def error(self, where: str, problem: str) -> ValueError:
        return ValueError(f"{self.path}: {where}: {problem}")

    def required(self, element: ET.Element, attribute: str, where: str, hint: str = "") -> str:
        value = element.get(attribute)
        if value is None or not value.strip():
            raise self.error(where, f"{'no' if value is None else 'an empty'} {attribute} "
                                    f"attribute{hint}")
        return value

    def typed(self, element: ET.Element, prefix: str, where: str) -> tuple[str, ET.Element]:
        """The one Real, Integer, Boolean or String child of a Connector or a Parameter."""
        children = [c for c in element if c.tag.startswith(f"{{{NS[prefix]}}}")]
        if len(children) != 1 or _local(children[0]) not in (f"{prefix}:{t}" for t in _TYPES):
            found = ", ".join(_local(c) for c in children) or "none"
            raise self.error(where, f"needs one of {', '.join(f'{prefix}:{t}' for t in _TYPES)}"
                                    f" (found: {found})")
        return children[0].tag.rpartition("}")[2], children[0]

    def number(self, element: ET.Element, attribute: str, where: str, default: float) -> float:
        text = element.get(attribute)
        try:
            value = default if text is None else fmi_value(attribute, "Real", text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise self.error(where, f"{attribute}={text!r} is not a finite number")
        return value

    def system(self, fmus: FmuFolders | None) -> SystemDescription:
        try:
            root = ET.parse(self.path).getroot()
        except (ET.ParseError, OSError) as error:
            raise ValueError(f"cannot read system structure {self.path}: {error}") from error
        if root.tag != _q("ssd:SystemStructureDescription"):
            raise ValueError(f"{self.path} is not an SSP system structure description "
                             f"(its root element is {_local(root)})")
        name = self.required(root, "name", "SystemStructureDescription")
        systems = root.findall("ssd:System", NS)
        if len(systems) != 1:
            raise self.error("SystemStructureDescription",
                             f"needs one System element, has {len(systems)}")
        system, components = systems[0], {}
        for i, element in enumerate(system.findall("ssd:Elements/*", NS), 1):
            component = self.component(element, i)
            if component.name in components:
                raise self.error(f"Component {i}", f"a second Component named '{component.name}'")
            components[component.name] = component
        if not components:
            raise self.error("System", "no Component in its Elements")
        connections = self.connections(system, components)
        try:
            description = SystemDescription(name, components, connections,
                                            description=system.get("description", ""),
                                            path=self.path, fmus=fmus)
        except ValueError as error:             # a name no file takes
            raise self.error("System", str(error)) from None
        experiment = root.find("ssd:DefaultExperiment", NS)
        if experiment is not None:
            self.experiment(experiment, description)
        return description

    def component(self, element: ET.Element, index: int) -> Component:
        if element.tag != _q("ssd:Component"):
            raise self.error(f"System, element {index} of Elements",
                             f"{_local(element)} is not read: only Components (FMUs)")
        name = self.required(element, "name", f"Component {index}")
        where = f"Component '{name}'"
        if "." in name:
            raise self.error(where, "a '.' in its name, which separates a component from "
                                    "its variables ('ship.psi')")
        kind = element.get("type", FMU_TYPE)
        if kind != FMU_TYPE:
            raise self.error(where, f"type {kind!r} is not read: only FMUs ({FMU_TYPE})")
        component = Component(name=name, source=self.required(element, "source", where))
        for j, connector in enumerate(element.findall("ssd:Connectors/ssd:Connector", NS), 1):
            connector_name = self.required(connector, "name", f"{where}, Connector {j}")
            at = f"{where}, Connector '{connector_name}'"
            causality = self.required(connector, "kind", at)
            if causality not in CONNECTOR_KINDS:
                raise self.error(at, f"kind {causality!r} is not one of "
                                     f"{', '.join(CONNECTOR_KINDS)}")
            if connector_name in component.connectors:
                raise self.error(at, "declared twice")
            component.connectors[connector_name] = causality, self.typed(connector, "ssc", at)[0]
        for binding in element.findall("ssd:ParameterBindings/ssd:ParameterBinding", NS):
            self.binding(binding, component, f"{where}, ParameterBinding")
        return component

    def binding(self, binding: ET.Element, component: Component, where: str) -> None:
        for attribute, what in (("source", "parameter values in another file"),
                                ("prefix", "a prefix to parameter names")):
            if binding.get(attribute):
                raise self.error(where, f"{attribute}={binding.get(attribute)!r}: {what} is "
                                        "not read; give the values inline")
        if binding.find("ssd:ParameterMapping", NS) is not None:
            raise self.error(where, "a ParameterMapping is not read")
        values = binding.find("ssd:ParameterValues", NS)
        if values is None:
            raise self.error(where, "no ParameterValues")
        parameters = values.findall("ssv:ParameterSet/ssv:Parameters/ssv:Parameter", NS)
        for k, p in enumerate(parameters, 1):
            name = self.required(p, "name", f"{where}, Parameter {k}")
            at = f"Component '{component.name}', Parameter '{name}'"
            if name in component.parameters:
                raise self.error(at, "given twice")
            type_name, value = self.typed(p, "ssv", at)
            at = f"{at}, ssv:{type_name}"
            text = self.required(value, "value", at)
            if value.get("unit") is not None:
                raise self.error(at, f"unit={value.get('unit')!r} is not read; give the value "
                                     "in the FMU's unit, without unit=")
            try:
                component.parameters[name] = fmi_value(f"{component.name}.{name}", type_name, text)
            except ValueError as error:
                raise self.error(at, str(error)) from None

    def connections(self, system: ET.Element, components: dict[str, Component]) -> list[Connection]:
        connections, fed = [], {}
        hint = " (connectors of the system itself are not read)"
        for i, c in enumerate(system.findall("ssd:Connections/ssd:Connection", NS), 1):
            connection = Connection(*(self.required(c, a, f"Connection {i}",
                                                    hint if "Element" in a else "")
                                      for a in ("startElement", "startConnector",
                                                "endElement", "endConnector")))
            where = f"Connection {i} ({connection})"
            for element in (connection.start_element, connection.end_element):
                if element not in components:
                    raise self.error(where, f"names the component '{element}', which the system "
                                            f"does not have; it has {', '.join(components)}")
            end = (connection.end_element, connection.end_connector)
            if end in fed:
                raise self.error(where, f"{'.'.join(end)} is fed already by Connection {fed[end]}")
            fed[end] = i
            connections.append(connection)
        return connections

    def experiment(self, experiment: ET.Element, description: SystemDescription) -> None:
        where = "DefaultExperiment"
        description.start_time = self.number(experiment, "startTime", where, 0.0)
        description.stop_time = self.number(experiment, "stopTime", where, description.stop_time)
        annotations = "ssd:Annotations/ssc:Annotation/"
        algorithm = experiment.find(f"{annotations}osp:Algorithm/osp:FixedStepAlgorithm", NS)
        if algorithm is not None:
            at = f"{where}, osp:FixedStepAlgorithm"
            self.required(algorithm, "baseStepSize", at)
            description.step_size = self.number(algorithm, "baseStepSize", at, math.nan)
        report = experiment.find(f"{annotations}sap:Report", NS)
        if report is not None:
            description.report = self.required(report, "kind", f"{where}, sap:Report")
        times = {"startTime": description.start_time, "stopTime": description.stop_time,
                 "baseStepSize": description.step_size}
        try:        # within what an FMU takes, a whole number of steps (fmukit.timebase)
            step_count(*times.values())
        except ValueError as error:
            raise self.error(where, str(error)) from None
        for name, t in times.items():
            if on_time_base(t) != t:
                raise self.error(where, f"{name} {t!r} s is not a whole number of nanoseconds, "
                                        "the time base (fmukit.timebase)")


def read_ssd(path: str | Path, fmus: FmuFolders | None = None) -> SystemDescription:
    """The system of a .ssd file (its FMUs looked for also in ``fmus``); ValueError naming the
    file, the element and the attribute for anything this module does not read."""
    return _Reader(Path(path)).system(fmus)


def ssv_value(value: float | int | bool | str) -> tuple[str, str]:
    """A parameter value as its SSP type and text: ('Real', repr(value)), ..."""
    if isinstance(value, bool):
        return "Boolean", str(value).lower()
    if isinstance(value, int):
        return "Integer", str(value)
    if isinstance(value, float):
        return "Real", repr(value)
    return "String", value


@dataclass(frozen=True)
class Units:
    """Connector units (component: connector: unit) and their BaseUnit attributes."""
    connectors: dict[str, dict[str, str]]
    definitions: dict[str, dict[str, float]]


def _el(parent: ET.Element, path: str, **attributes: str) -> ET.Element:
    """New elements under ``parent``, one in the other ("ssd:A/ssc:B"), attributes on the last."""
    *chain, last = path.split("/")
    for tag in chain:
        parent = ET.SubElement(parent, _q(tag))
    return ET.SubElement(parent, _q(last), **attributes)


def write_ssd(system: SystemDescription, path: str | Path,
              sources: dict[str, str] | None = None, units: Units | None = None) -> None:
    """Write ``system`` as a .ssd, ``sources`` replacing component sources by name, ``units`` on
    connectors; the step in OSP's and OpenModelica's annotations, the report's kind in ours."""
    unit_of = units.connectors if units else {}
    name = re.sub(r"\W", "_", system.name, flags=re.ASCII)      # an identifier every tool
    name = f"_{name}" if name[:1].isdigit() else name           # takes (OMSimulator's too)
    root = ET.Element(_q("ssd:SystemStructureDescription"), version="1.0", name=name)
    sys_el = _el(root, "ssd:System", name=name, description=system.description)
    elements = _el(sys_el, "ssd:Elements")
    for c in system.components.values():
        comp = _el(elements, "ssd:Component", name=c.name,
                   source=(sources or {}).get(c.name, c.source), type=FMU_TYPE)
        connectors = _el(comp, "ssd:Connectors")
        for name, (kind, type_name) in c.connectors.items():
            unit = unit_of.get(c.name, {}).get(name)
            _el(_el(connectors, "ssd:Connector", name=name, kind=kind), f"ssc:{type_name}",
                **({"unit": unit} if unit else {}))
        if c.parameters:
            params = _el(comp, "ssd:ParameterBindings/ssd:ParameterBinding/ssd:ParameterValues/"
                               "ssv:ParameterSet", version="1.0", name="scenario")
            params = _el(params, "ssv:Parameters")
            for name, value in c.parameters.items():
                type_name, text = ssv_value(value)
                _el(_el(params, "ssv:Parameter", name=name), f"ssv:{type_name}", value=text)
    connections = _el(sys_el, "ssd:Connections")
    for k in system.connections:
        _el(connections, "ssd:Connection", startElement=k.start_element,
            startConnector=k.start_connector, endElement=k.end_element,
            endConnector=k.end_connector)
    _el(_el(sys_el, "ssd:Annotations/ssc:Annotation", type="org.openmodelica"),
        "oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster", description="oms-ma",
        stepSize=repr(system.step_size))
    used = sorted({u for by_name in unit_of.values() for u in by_name.values()})
    if used:                              # SSP 1.0: Units after System, before the experiment
        definitions = _el(root, "ssd:Units")
        for unit in used:
            _el(_el(definitions, "ssc:Unit", name=unit), "ssc:BaseUnit",
                **{k: repr(v) if isinstance(v, float) else str(v)
                   for k, v in units.definitions[unit].items()})
    experiment = _el(root, "ssd:DefaultExperiment", startTime=repr(system.start_time),
                     stopTime=repr(system.stop_time))
    annotations = _el(experiment, "ssd:Annotations")
    _el(_el(annotations, "ssc:Annotation", type="com.opensimulationplatform"),
        "osp:Algorithm/osp:FixedStepAlgorithm", baseStepSize=repr(system.step_size))
    _el(_el(annotations, "ssc:Annotation", type="org.ship-autopilot-cosim"), "sap:Report",
        kind=system.report)
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)
