"""Your own autopilot in the paper's scenarios (docs/own_autopilot.md): the port contract checked,
a port in another unit refused, not converted (a run never rests on a guess)."""
from __future__ import annotations

import copy
from pathlib import Path

import fmpy
from fmpy.model_description import ModelDescription

import fmukit.autopilot
from fmubuild.instantiate import InstantiationFailed, instantiate_in_child
from fmukit.variables import UNITS

from ..core.system import close_matches, did_you_mean
from ..core.ssd import Connection, SystemDescription
from ..core.units import unit_of

COMPONENT = "autopilot"
PORTS = {v.name: (v.causality, v.unit) for v in fmukit.autopilot.PORTS}
DESCRIPTIONS = {v.name: v.description for v in fmukit.autopilot.PORTS}
PORT_TYPES = {"2.0": "Real", "3.0": "Float64"}      # FMI version: the type of its ports
_LISTED = {c: ", ".join(f"{n} ({unit})" for n, (k, unit) in PORTS.items() if k == c)
           for c in ("input", "output")}               # the contract in words


class AutopilotError(ValueError):
    """An FMU that cannot serve as an autopilot; the message names the file and the port."""


def _listing(description: ModelDescription) -> str:
    kinds = {}
    for v in description.modelVariables:
        kinds.setdefault(v.causality, []).append(f"{v.name} ({v.type}"
                                                 + (f", {v.unit})" if v.unit else ")"))
    return "; ".join(f"{k}s: {', '.join(names)}" for k, names in kinds.items()
                     if k in ("input", "output", "parameter"))


def port_problems(description: ModelDescription, port_map: dict[str, str]) -> list[str]:
    """Every way the FMU's variables break the port contract, each with what it expects."""
    variables = {v.name: v for v in description.modelVariables}
    real = PORT_TYPES[description.fmiVersion]
    problems = []
    for port, (causality, unit) in PORTS.items():
        name = port_map.get(port, port)
        mapped = f"'{name}' (for {port})" if name != port else f"'{port}'"
        variable = variables.get(name)
        if variable is None:
            problems.append(f"no port {mapped}: expected a {real} {causality} in {unit} "
                            f"({DESCRIPTIONS[port]}){did_you_mean(close_matches(name, variables))}")
            continue
        if variable.causality != causality or variable.type != real:
            problems.append(f"port {mapped} is of causality {variable.causality} and type "
                            f"{variable.type}: expected a {real} {causality} in {unit}")
        declared = unit_of(variable)
        if declared and declared != unit:
            known = UNITS.get(declared)
            scale = (f" (1 {declared} = {known[1] / UNITS[unit][1]:.6g} {unit})"
                     if known and known[0] == UNITS[unit][0] else "")
            problems.append(f"port {mapped} is in {declared}: expected {unit}; the interfaces "
                            f"are in SI units, angles in radians: declare {name} in {unit} and "
                            f"convert inside the FMU{scale}")
    return problems


def check_autopilot(fmu: str | Path, port_map: dict[str, str] | None = None,
                    trial: bool = False) -> ModelDescription:
    """Its model description if the FMU keeps the port contract (``trial``: and instantiates
    in a child process), else AutopilotError."""
    fmu, port_map = Path(fmu), port_map or {}
    if not fmu.is_file():
        raise AutopilotError(f"autopilot FMU {fmu} not found")
    try:
        description = fmpy.read_model_description(str(fmu))
    except Exception as error:
        raise AutopilotError(f"{fmu} is not an FMU, or not a readable one "
                             f"({type(error).__name__}: {error})") from None
    must = f"an autopilot must be an FMI {' or '.join(PORT_TYPES)} co-simulation FMU"
    if description.fmiVersion not in PORT_TYPES:
        raise AutopilotError(f"{fmu} is an FMI {description.fmiVersion} FMU; {must}")
    if description.coSimulation is None:
        raise AutopilotError(f"{fmu} is a model-exchange FMU only; {must}")
    platforms = [p for p in fmpy.supported_platforms(str(fmu)) if p != "c-code"]
    if fmpy.platform not in platforms:
        raise AutopilotError(f"{fmu} has no binary for this platform ({fmpy.platform}); it has "
                             f"{', '.join(platforms) or 'none'}")
    if unknown := sorted(set(port_map) - set(PORTS)):
        close = [m for u in unknown for m in close_matches(u, PORTS)]
        raise AutopilotError(f"{fmu}: --map names {', '.join(map(repr, unknown))}, which "
                             f"{'is not a port' if len(unknown) == 1 else 'are not ports'} "
                             f"of an autopilot ({', '.join(PORTS)}){did_you_mean(close)}")
    problems, real = port_problems(description, port_map), PORT_TYPES[description.fmiVersion]
    if problems:
        raise AutopilotError(f"{fmu} does not keep the autopilot contract of an FMI "
                             f"{description.fmiVersion} FMU ({real} inputs {_LISTED['input']} "
                             f"and a {real} output {_LISTED['output']}):\n"
                             + "".join(f"  - {p}\n" for p in problems)
                             + f"It has {_listing(description)}. Map other names with --map "
                             "PORT=NAME (--map psi=heading)")
    names = [port_map.get(port, port) for port in PORTS]
    if twice := sorted({n for n in names if names.count(n) > 1}):      # as in an .ssd
        ports = " and ".join(p for p, n in zip(PORTS, names) if n in twice)
        raise AutopilotError(f"{fmu}: --map wires {ports} onto one variable "
                             f"({', '.join(twice)}); each port needs its own")
    if trial:
        try:
            instantiate_in_child(fmu)
        except InstantiationFailed as failed:
            raise AutopilotError(str(failed)) from None
    return description


def with_autopilot(system: SystemDescription, fmu: str | Path,
                   port_map: dict[str, str] | None = None,
                   name: str | None = None) -> SystemDescription:
    """A copy of a course-keeping system with ``fmu`` as its autopilot, or AutopilotError."""
    fmu, port_map = Path(fmu).resolve(), port_map or {}
    if COMPONENT not in system.components or system.report != "course_keeping":
        raise AutopilotError(f"scenario {system.name!r} has no autopilot to replace; "
                             "--autopilot works with the course-keeping scenarios")
    check_autopilot(fmu, port_map)
    name = name or fmu.stem
    new = copy.deepcopy(system)
    autopilot = new.components[COMPONENT]
    autopilot.source, autopilot.parameters = str(fmu), {}
    autopilot.connectors = {port_map.get(p, p): (causality, "Real")
                            for p, (causality, _) in PORTS.items()}

    def port(element: str, connector: str) -> str:
        return port_map.get(connector, connector) if element == COMPONENT else connector
    new.connections = [Connection(c.start_element, port(c.start_element, c.start_connector),
                                  c.end_element, port(c.end_element, c.end_connector))
                       for c in system.connections]
    new.name = f"{system.name}-{name}"
    new.description = (f"autopilot {name} ({fmu.name}) in the {system.name} scenario "
                       f"(its route, ship and sea)")
    return new
