"""Read and write SSP 1.0 system structure descriptions (.ssd) of a flat system.

The subset used here is the one OSP libcosim, ecos and fmpy all read: one system of
FMU components with connectors, inline parameter sets (ssv:Real, Integer, Boolean,
String), connections, and a DefaultExperiment whose OSP annotation gives the fixed
step. ``write_ssd`` also gives the step in OpenModelica's annotation on the System,
the only place OMSimulator's command line learns the system's type and step from
(without it, it aborts with '[NewSystem] internal error'). This project adds one
annotation of its own (type ``REPORT_ANNOTATION``) naming the kind of analysis a run of
the system gets (``cosim.analysis.kinds``); other tools ignore it. ``read_ssd`` refuses what is not in this subset (nested
systems, connectors of the system itself, parameter values in .ssv files or with
units, ...) or not well formed, naming the file, the element and the attribute.
"""
from __future__ import annotations

import copy
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fmubuild.project import C_FMUS, FMU_DIR, FMU_DIRS, FMUS
from fmukit.timebase import MAX_TIME, on_time_base, step_count

from .errors import FmuNotFound
from .values import fmi_value

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "sap": "https://github.com/ship-autopilot-cosim/annotations",
    "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
}
OSP_ANNOTATION = "com.opensimulationplatform"
OMS_ANNOTATION = "org.openmodelica"
REPORT_ANNOTATION = "org.ship-autopilot-cosim"
PARAMETER_SET = "scenario"
_TYPES = ("Real", "Integer", "Boolean", "String")
FMU_TYPE = "application/x-fmu-sharedlibrary"
CONNECTOR_KINDS = ("input", "output", "inout", "parameter", "calculatedParameter")

FMU_SEARCH_PATH = [FMU_DIR]
"""Folders searched for an FMU not found where its .ssd points, by its path after its last
``fmus`` folder (``fmi3/ship.fmu`` for ``../../fmus/fmi3/ship.fmu``), else by its file
name: the project's fmus/, so that a scenario copied anywhere still finds the project's
FMUs, of the FMI version it names."""

for _prefix, _uri in NS.items():
    ET.register_namespace(_prefix, _uri)



def split_name(name: str) -> tuple[str, str]:
    """'ship.psi' -> ('ship', 'psi'): a variable by its component; ValueError naming ``name``
    if it is not of the form component.variable."""
    component, dot, variable = name.partition(".") if isinstance(name, str) else ("", "", "")
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
        folder), then a file of that name in each of ``FMU_SEARCH_PATH``; an absolute
        source is only itself (another file of its name would run in its place unseen)."""
        source = Path(self.components[component].source)
        base = self.path.parent if self.path else Path.cwd()
        parts = source.parts
        tail = Path(*parts[len(parts) - parts[::-1].index("fmus"):]) if "fmus" in parts[:-1] \
            else Path(source.name)
        elsewhere = [] if source.is_absolute() else [d / tail for d in FMU_SEARCH_PATH]
        candidates = [(base / source).resolve(), *elsewhere]
        return list(dict.fromkeys(candidates))

    def fmu_path(self, component: str) -> Path:
        """The first of ``fmu_candidates`` that exists; FileNotFoundError naming all tried."""
        candidates = self.fmu_candidates(component)
        for path in candidates:
            if path.is_file():
                return path
        source = Path(self.components[component].source)
        ours = source.stem in FMUS
        twin = 3 in map(project_fmi, candidates)
        hint = (f"one of this project's {'FMI 3.0 ' if twin else ''}FMUs, not built" if ours
                else f"check the source of component '{component}' in {self.path or 'the system'}")
        raise FmuNotFound(f"FMU for '{component}' not found; tried "
                          f"{', '.join(map(str, candidates))}; {hint}", ours)


def project_fmi(path: Path) -> int | None:
    """The FMI version of the folder of this project's built FMUs that ``path`` is in
    (``fmubuild.project.FMU_DIRS``), if it is one of them by name; None for any other."""
    if path.stem not in FMUS and path.stem not in C_FMUS:
        return None
    return next((fmi for fmi, folder in FMU_DIRS.items() if path.parent == folder), None)


def with_fmi(system: SystemDescription, fmi: int) -> SystemDescription:
    """A copy of ``system`` whose components that run this project's FMUs (found in, or
    missing from, one of its build folders) take those of FMI version ``fmi``: fmus/ for
    2, fmus/fmi3/ for 3 (``fmubuild.project.FMU_DIRS``); other FMUs stay as they are."""
    if fmi not in FMU_DIRS:
        raise ValueError(f"FMI {fmi}: this project's FMUs are built for FMI "
                         f"{' and '.join(f'{v}.0' for v in FMU_DIRS)}")
    new = copy.deepcopy(system)
    for name, component in new.components.items():
        candidates = system.fmu_candidates(name)
        found = next((p for p in candidates if p.is_file()), None)
        if any(project_fmi(p) for p in ([found] if found else candidates)):
            component.source = str(FMU_DIRS[fmi] / Path(component.source).name)
    return new


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _local(element: ET.Element) -> str:
    """An element's tag as the file writes it: 'ssv:Real'."""
    uri, _, tag = element.tag.rpartition("}")
    prefix = next((p for p, u in NS.items() if f"{{{u}" == uri), None)
    return f"{prefix}:{tag}" if prefix else tag


class _Reader:
    """Reads one .ssd; every error names the file, the element and the attribute."""

    def __init__(self, path: Path):
        self.path = path

    def error(self, where: str, problem: str) -> ValueError:
        return ValueError(f"{self.path}: {where}: {problem}")

    def required(self, element: ET.Element, attribute: str, where: str,
                 hint: str = "") -> str:
        """The attribute's value; an error if it is missing or blank."""
        value = element.get(attribute)
        if value is None or not value.strip():
            raise self.error(where, f"{'no' if value is None else 'an empty'} {attribute} "
                                    f"attribute{hint}")
        return value

    def typed(self, element: ET.Element, prefix: str, where: str) -> tuple[str, ET.Element]:
        """The one Real, Integer, Boolean or String child of a Connector (ssc) or a
        Parameter (ssv), by its type's name."""
        children = [c for c in element if c.tag.startswith(f"{{{NS[prefix]}}}")]
        known = [c for c in children if c.tag.rpartition("}")[2] in _TYPES]
        if len(children) != 1 or len(known) != 1:
            found = ", ".join(_local(c) for c in children) or "none"
            raise self.error(where, f"needs one of {', '.join(f'{prefix}:{t}' for t in _TYPES)}"
                                    f" (found: {found})")
        return known[0].tag.rpartition("}")[2], known[0]

    def number(self, element: ET.Element, attribute: str, where: str,
               default: float) -> float:
        """A finite number from an attribute, ``default`` where it is absent."""
        text = element.get(attribute)
        if text is None:
            return default
        try:
            value = fmi_value(attribute, "Real", text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise self.error(where, f"{attribute}={text!r} is not a finite number")
        return value

    def system(self) -> SystemDescription:
        try:
            root = ET.parse(self.path).getroot()
        except (ET.ParseError, OSError) as error:
            raise ValueError(f"cannot read system structure {self.path}: {error}") from error
        if root.tag != _q("ssd", "SystemStructureDescription"):
            raise ValueError(f"{self.path} is not an SSP system structure description "
                             f"(its root element is {_local(root)})")
        name = self.required(root, "name", "SystemStructureDescription")
        systems = root.findall("ssd:System", NS)
        if len(systems) != 1:
            raise self.error("SystemStructureDescription", f"needs one System element, has "
                                                           f"{len(systems)}")
        system = systems[0]
        components: dict[str, Component] = {}
        for i, element in enumerate(system.findall("ssd:Elements/*", NS), 1):
            if element.tag != _q("ssd", "Component"):
                raise self.error(f"System, element {i} of Elements",
                                 f"{_local(element)} is not read: only Components (FMUs)")
            component = self.component(element, i)
            if component.name in components:
                raise self.error(f"Component {i}", f"a second Component named "
                                                   f"'{component.name}'")
            components[component.name] = component
        if not components:
            raise self.error("System", "no Component in its Elements")
        connections = self.connections(system, components)
        description = SystemDescription(name=name, components=components,
                                        connections=connections,
                                        description=system.get("description", ""),
                                        path=self.path)
        experiment = root.find("ssd:DefaultExperiment", NS)
        if experiment is not None:
            self.experiment(experiment, description)
        return description

    def component(self, element: ET.Element, index: int) -> Component:
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
            component.connectors[connector_name] = (causality,
                                                    self.typed(connector, "ssc", at)[0])
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
        for k, p in enumerate(values.findall("ssv:ParameterSet/ssv:Parameters/ssv:Parameter",
                                             NS), 1):
            name = self.required(p, "name", f"{where}, Parameter {k}")
            at = f"Component '{component.name}', Parameter '{name}'"
            if name in component.parameters:
                raise self.error(at, "given twice")
            type_name, value = self.typed(p, "ssv", at)
            text = self.required(value, "value", f"{at}, ssv:{type_name}")
            if value.get("unit") is not None:
                raise self.error(f"{at}, ssv:{type_name}", f"unit={value.get('unit')!r} is "
                                 "not read; give the value in the FMU's unit, without unit=")
            try:
                component.parameters[name] = fmi_value(f"{component.name}.{name}", type_name,
                                                       text)
            except ValueError as error:
                raise self.error(f"{at}, ssv:{type_name}", str(error)) from None

    def connections(self, system: ET.Element, components: dict[str, Component]
                    ) -> list[Connection]:
        connections, fed = [], {}
        hint = " (connectors of the system itself are not read)"
        for i, c in enumerate(system.findall("ssd:Connections/ssd:Connection", NS), 1):
            where = f"Connection {i}"
            connection = Connection(*(self.required(c, a, where, hint if "Element" in a else "")
                                      for a in ("startElement", "startConnector",
                                                "endElement", "endConnector")))
            where = f"Connection {i} ({connection})"
            for element in (connection.start_element, connection.end_element):
                if element not in components:
                    raise self.error(where, f"names the component '{element}', which the "
                                            f"system does not have; it has "
                                            f"{', '.join(components)}")
            end = (connection.end_element, connection.end_connector)
            if end in fed:
                raise self.error(where, f"{'.'.join(end)} is fed already by Connection "
                                        f"{fed[end]}")
            fed[end] = i
            connections.append(connection)
        return connections

    def experiment(self, experiment: ET.Element, description: SystemDescription) -> None:
        where = "DefaultExperiment"
        description.start_time = self.number(experiment, "startTime", where, 0.0)
        description.stop_time = self.number(experiment, "stopTime", where,
                                            description.stop_time)
        if not description.stop_time > description.start_time:
            raise self.error(where, f"stopTime {description.stop_time!r} is not after "
                                    f"startTime {description.start_time!r}")
        annotations = "ssd:Annotations/ssc:Annotation/"
        algorithm = experiment.find(f"{annotations}osp:Algorithm/osp:FixedStepAlgorithm", NS)
        if algorithm is not None:
            at = f"{where}, osp:FixedStepAlgorithm"
            self.required(algorithm, "baseStepSize", at)
            description.step_size = self.number(algorithm, "baseStepSize", at, math.nan)
            if not description.step_size > 0:
                raise self.error(at, f"baseStepSize {description.step_size!r} is not > 0")
        report = experiment.find(f"{annotations}sap:Report", NS)
        if report is not None:
            description.report = self.required(report, "kind", f"{where}, sap:Report")
        for name, t in (("startTime", description.start_time),
                        ("stopTime", description.stop_time),
                        ("baseStepSize", description.step_size)):
            if abs(t) > MAX_TIME:           # beyond what the FMUs take (and 2^63 ns)
                raise self.error(where, f"{name} {t!r} s is beyond +-{MAX_TIME:g} s, the "
                                        "times an FMU takes (fmukit.timebase)")
            if on_time_base(t) != t:
                raise self.error(where, f"{name} {t!r} s is not a whole number of "
                                        "nanoseconds, the time base (fmukit.timebase)")
        try:
            step_count(description.start_time, description.stop_time, description.step_size)
        except ValueError as error:
            raise self.error(where, str(error)) from None


def read_ssd(path: str | Path) -> SystemDescription:
    """Parse a .ssd file of the subset this module reads; ValueError naming the file, the
    element and the attribute for anything else (a parameter's value read by the rules
    of ``cosim.core.values.fmi_value``)."""
    return _Reader(Path(path)).system()


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
    """The units of a system's connectors, as its FMUs declare them: component: connector:
    unit name, and each unit's definition (BaseUnit exponents kg m s A K mol cd rad, factor,
    offset: the same attributes in FMI 2.0 and SSP 1.0)."""
    connectors: dict[str, dict[str, str]]
    definitions: dict[str, dict[str, float]]


def write_ssd(system: SystemDescription, path: str | Path,
              sources: dict[str, str] | None = None, units: Units | None = None) -> None:
    """Write ``system`` as a .ssd; ``sources`` replaces component sources by name; with
    ``units``, each connector carries its unit, defined in the file's ssd:Units.

    The fixed step goes into two annotations (SSP 1.0, 'Annotations'): OSP's
    FixedStepAlgorithm on the DefaultExperiment, and OpenModelica's FixedStepMaster
    ('oms-ma', its weakly coupled master) on the System, as OMSimulator writes it."""
    root = ET.Element(_q("ssd", "SystemStructureDescription"), version="1.0", name=system.name)
    sys_el = ET.SubElement(root, _q("ssd", "System"), name=system.name,
                           description=system.description)
    elements = ET.SubElement(sys_el, _q("ssd", "Elements"))
    for c in system.components.values():
        source = (sources or {}).get(c.name, c.source)
        comp = ET.SubElement(elements, _q("ssd", "Component"), name=c.name, source=source,
                             type=FMU_TYPE)
        connectors = ET.SubElement(comp, _q("ssd", "Connectors"))
        for name, (kind, type_name) in c.connectors.items():
            connector = ET.SubElement(connectors, _q("ssd", "Connector"), name=name, kind=kind)
            unit = units.connectors.get(c.name, {}).get(name) if units else None
            ET.SubElement(connector, _q("ssc", type_name), **({"unit": unit} if unit else {}))
        if c.parameters:
            binding = ET.SubElement(ET.SubElement(comp, _q("ssd", "ParameterBindings")),
                                    _q("ssd", "ParameterBinding"))
            values = ET.SubElement(binding, _q("ssd", "ParameterValues"))
            pset = ET.SubElement(values, _q("ssv", "ParameterSet"), version="1.0",
                                 name=PARAMETER_SET)
            params = ET.SubElement(pset, _q("ssv", "Parameters"))
            for name, value in c.parameters.items():
                type_name, text = ssv_value(value)
                p = ET.SubElement(params, _q("ssv", "Parameter"), name=name)
                ET.SubElement(p, _q("ssv", type_name), value=text)
    connections = ET.SubElement(sys_el, _q("ssd", "Connections"))
    for k in system.connections:
        ET.SubElement(connections, _q("ssd", "Connection"), startElement=k.start_element,
                      startConnector=k.start_connector, endElement=k.end_element,
                      endConnector=k.end_connector)
    oms = ET.SubElement(ET.SubElement(sys_el, _q("ssd", "Annotations")), _q("ssc", "Annotation"),
                        type=OMS_ANNOTATION)
    information = ET.SubElement(ET.SubElement(oms, _q("oms", "Annotations")),
                                _q("oms", "SimulationInformation"))
    ET.SubElement(information, _q("oms", "FixedStepMaster"), description="oms-ma",
                  stepSize=repr(system.step_size))
    used = sorted({u for by_name in (units.connectors if units else {}).values()
                   for u in by_name.values()})
    if used:                              # SSP 1.0: Units after System, before the experiment
        definitions = ET.SubElement(root, _q("ssd", "Units"))
        for unit in used:
            ET.SubElement(ET.SubElement(definitions, _q("ssc", "Unit"), name=unit),
                          _q("ssc", "BaseUnit"),
                          **{k: repr(v) if isinstance(v, float) else str(v)
                             for k, v in units.definitions[unit].items()})
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
