"""SSP packages for other FMI tools: a scenario exported as one self-contained .ssp file.

The package is a zip holding SystemStructure.ssd (components, connections, the
scenario's parameter values, the fixed step as an OSP annotation) and
resources/<fmu>.fmu for every FMU it uses. OSP libcosim, ecos, fmpy and
OMSimulator load it unchanged (see README, "Using the FMUs elsewhere"). It is
written whole or not at all: a full disk or a kill leaves no package, or the
previous one (``cosim.core.files``).
"""
from __future__ import annotations

import tempfile
import zipfile
from pathlib import Path

from .. import scenarios
from ..core.files import whole_file
from ..core.ssd import SystemDescription, read_ssd, write_ssd

SSD_NAME = "SystemStructure.ssd"


def export(scenario: str | Path, out: Path, overrides: dict[str, dict] | None = None,
           autopilot: str | Path | None = None, port_map: dict[str, str] | None = None,
           name: str | None = None) -> Path:
    """Write out/<label>.ssp (``scenarios.label``): the scenario, with ``autopilot`` in
    place of its own if given, and ``overrides`` changing parameter values by component."""
    system = scenarios.load(scenario, autopilot, port_map, name)
    for component, values in system.parameters(overrides).items():
        system.components[component].parameters = values
    fmus = {c: system.fmu_path(c) for c in system.components}     # FileNotFoundError
    by_name: dict[str, Path] = {}
    for component, path in fmus.items():
        if by_name.setdefault(path.name, path) != path:
            raise ValueError(f"two FMUs named {path.name} ({by_name[path.name]} and {path}) "
                             "cannot both go into resources/; rename one")
    sources = {c: f"resources/{path.name}" for c, path in fmus.items()}
    target = out / f"{scenarios.label(scenario, autopilot, name)}.ssp"
    with tempfile.TemporaryDirectory() as tmp:
        ssd = Path(tmp) / SSD_NAME
        write_ssd(system, ssd, sources)
        with whole_file(target) as partial, \
                zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as package:
            package.write(ssd, SSD_NAME)
            for path in sorted(set(fmus.values())):
                package.write(path, f"resources/{path.name}")
    return target


def read_package(ssp: Path) -> SystemDescription:
    """The system description inside an SSP package."""
    with tempfile.TemporaryDirectory() as tmp:
        with zipfile.ZipFile(ssp) as package:
            package.extract(SSD_NAME, tmp)
        return read_ssd(Path(tmp) / SSD_NAME)
