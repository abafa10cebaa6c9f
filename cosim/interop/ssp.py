"""SSP packages for other FMI tools: a scenario exported as one self-contained .ssp file.

The package is a zip holding SystemStructure.ssd (components, connections, the
scenario's parameter values, the fixed step as OSP's and OpenModelica's annotations,
``cosim.core.ssd.write_ssd``) and resources/<fmu>.fmu for every FMU it uses. Beside
it, a folder of the same name holds OSP's OspSystemStructure.xml and the FMUs
(``cosim.interop.osp``). OSP libcosim, ecos, fmpy and OMSimulator load the package
unchanged (docs/interop.md). The guidance's route is written in its numeric form
(``autopilot_fmu.guidance.numeric_route``), because OMSimulator and fmpy's SSP runner
apply no String binding; ``unapplied_strings`` names any String binding left that
such a tool would silently drop. Each is written whole or not at all: a full disk or
a kill leaves no package, or the previous one (``cosim.core.files``).

``export(..., fmi=3)`` packs this project's FMI 3.0 twins (fmus/fmi3/) in place of the
FMUs the scenario names; SSP 1.0 types their Float64 connectors as ssc:Real, as
FMI 2.0's. ecos and OMSimulator run such a package; libcosim and fmpy's SSP runner take
FMI 2.0 FMUs only (``fmi_versions`` says which a package holds; ``FMI2_ONLY``).
"""
from __future__ import annotations

import io
import shutil
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree

from autopilot_fmu.guidance import ROUTE_PARAMETERS, numeric_route, route

from .. import scenarios
from ..core.files import fresh_folder, whole_file
from ..core.fmi import read_description
from ..core.ssd import SystemDescription, Units, read_ssd, write_ssd
from .osp import OSP_FILE, read_osp, write_osp

SSD_NAME = "SystemStructure.ssd"
FMI2_ONLY = {"libcosim": "OSP libcosim", "fmpy": "fmpy's SSP runner"}
"""The engines (``cosim.interop.engines``) that run FMI 2.0 FMUs only: libcosimpy 0.0.6's
libcosim, and fmpy's SSP runner (its FMU2Slave); ecos and OMSimulator take FMI 2.0 and
3.0."""


def _with_numeric_route(system: SystemDescription, fmus: dict[str, Path]) -> None:
    """Replace a String route by its numbers in each component whose FMU declares both
    forms (our guidance); ValueError if the two forms disagree or the route is too long."""
    for name, component in system.components.items():
        if not isinstance(component.parameters.get("waypoints"), str):
            continue
        declared = {v.name for v in read_description(fmus[name], name).modelVariables}
        if declared.issuperset(ROUTE_PARAMETERS):
            route(component.parameters)
            parameters = dict(component.parameters)
            parameters.update(numeric_route(parameters.pop("waypoints")))
            component.parameters = parameters


_EXPONENTS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def connector_units(system: SystemDescription, fmus: dict[str, Path]) -> Units:
    """Each connector's unit and each unit's definition, from the FMUs' model descriptions
    (a connector whose variable declares no unit gets none)."""
    connectors: dict[str, dict[str, str]] = {}
    definitions: dict[str, dict[str, float]] = {}
    for name, component in system.components.items():
        described = read_description(fmus[name], name)
        by_name = {v.name: v.unit or (v.declaredType.unit if v.declaredType else None)
                   for v in described.modelVariables}
        connectors[name] = {c: by_name[c] for c in component.connectors if by_name.get(c)}
        for unit in described.unitDefinitions:
            base = unit.baseUnit
            definitions[unit.name] = {
                **{k: getattr(base, k) for k in _EXPONENTS if base and getattr(base, k)},
                **({"factor": base.factor} if base and base.factor != 1.0 else {}),
                **({"offset": base.offset} if base and base.offset != 0.0 else {})}
    for name, by_connector in connectors.items():
        for connector, unit in by_connector.items():
            if unit not in definitions:
                raise ValueError(f"{name}.{connector}: unit {unit!r} has no definition in its "
                                 "FMU's model description")
    return Units(connectors, definitions)


def export(scenario: str | Path, out: Path, overrides: dict[str, dict] | None = None,
           autopilot: str | Path | None = None, port_map: dict[str, str] | None = None,
           name: str | None = None, fmi: int | None = None) -> Path:
    """Write out/<label>.ssp (``scenarios.label``) and out/<label>/ with OSP's
    OspSystemStructure.xml and the FMUs: the scenario, with this project's FMUs of FMI
    version ``fmi`` if given (``scenarios.load``), ``autopilot`` in place of its own if
    given, and ``overrides`` changing parameter values by component."""
    system = scenarios.load(scenario, autopilot, port_map, name, fmi)
    for component, values in system.parameters(overrides).items():
        system.components[component].parameters = values
    fmus = {c: system.fmu_path(c) for c in system.components}     # FileNotFoundError
    by_name: dict[str, Path] = {}
    for component, path in fmus.items():
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


def fmi_version(fmu: zipfile.ZipFile) -> str:
    """The fmiVersion of an FMU ("2.0", "3.0"), from its modelDescription.xml."""
    return ElementTree.fromstring(fmu.read("modelDescription.xml")).get("fmiVersion", "")


def fmi_versions(path: Path) -> dict[str, str]:
    """Each component's FMI version, from its FMU in an SSP package or in an OSP folder
    (a .ssp, else the folder or its OspSystemStructure.xml)."""
    if path.suffix.lower() == ".ssp":
        with zipfile.ZipFile(path) as package:
            sources = {name: io.BytesIO(package.read(component.source))
                       for name, component in read_package(path).components.items()}
    else:
        folder = path if path.is_dir() else path.parent
        sources = {name: folder / component.source
                   for name, component in read_osp(path).components.items()}
    versions = {}
    for name, source in sources.items():
        with zipfile.ZipFile(source) as fmu:
            versions[name] = fmi_version(fmu)
    return versions


def read_package(ssp: Path) -> SystemDescription:
    """The system description inside an SSP package."""
    with tempfile.TemporaryDirectory() as tmp:
        with zipfile.ZipFile(ssp) as package:
            package.extract(SSD_NAME, tmp)
        return read_ssd(Path(tmp) / SSD_NAME)


def unapplied_strings(ssp: Path) -> dict[str, tuple[str, str]]:
    """The package's String bindings that a tool applying none (OMSimulator, fmpy's SSP
    runner) would drop without a word, changing the run: 'component.variable':
    (value, the FMU's default), for each whose value is not its FMU's default."""
    system = read_package(ssp)
    dropped = {}
    with tempfile.TemporaryDirectory() as tmp:
        with zipfile.ZipFile(ssp) as package:
            package.extractall(tmp)
        for name, component in system.components.items():
            strings = {v: value for v, value in component.parameters.items()
                       if isinstance(value, str)}
            if not strings:
                continue
            starts = {v.name: v.start for v in read_description(
                Path(tmp) / component.source, name).modelVariables}
            dropped.update({f"{name}.{v}": (value, starts[v]) for v, value in strings.items()
                            if value != starts[v]})
    return dropped
