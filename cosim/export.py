"""Export a scenario as a self-contained SSP package for other FMI tools.

    python -m cosim.export calm_pd                 -> results/ssp/calm_pd.ssp
    python -m cosim.export --all --out DIR         -> the paper's four scenarios

The package is a zip holding SystemStructure.ssd (components, connections, the
scenario's parameter values, the fixed step as an OSP annotation) and
resources/<fmu>.fmu for every FMU it uses. OSP libcosim, ecos, fmpy and
OMSimulator load it unchanged (see README, "Using the FMUs elsewhere").
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import zipfile
from pathlib import Path

from .fmu import BUILD_HINT
from .run import PAPER_SCENARIOS, SCENARIO_DIR, scenarios, writable_folder
from .ssd import read_ssd, write_ssd

SSD_NAME = "SystemStructure.ssd"


def export(name: str, out: Path, overrides: dict[str, dict] | None = None) -> Path:
    """Write out/<name>.ssp; ``overrides`` changes parameter values by component."""
    system = read_ssd(SCENARIO_DIR / f"{name}.ssd")
    for component, values in (overrides or {}).items():
        system.components[component].parameters.update(values)
    fmus = {c: system.fmu_path(c) for c in system.components}
    for component, path in fmus.items():
        if not path.is_file():
            raise FileNotFoundError(f"FMU for '{component}' not found: {path}; {BUILD_HINT}")
    sources = {c: f"resources/{path.name}" for c, path in fmus.items()}
    target = out / f"{name}.ssp"
    with tempfile.TemporaryDirectory() as tmp:
        ssd = Path(tmp) / SSD_NAME
        write_ssd(system, ssd, sources)
        with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as package:
            package.write(ssd, SSD_NAME)
            for path in sorted(set(fmus.values())):
                package.write(path, f"resources/{path.name}")
    return target


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.export",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("scenario", nargs="?", help=f"one of: {', '.join(scenarios())}")
    parser.add_argument("--all", action="store_true", help="the paper's four scenarios")
    parser.add_argument("--out", type=Path, default=Path("results/ssp"), help="output folder")
    args = parser.parse_args(argv)
    if args.all == bool(args.scenario):
        parser.error("give one SCENARIO or --all")
    names = PAPER_SCENARIOS if args.all else [args.scenario]
    for name in names:
        if name not in scenarios():
            parser.error(f"unknown scenario {name!r}; valid scenarios: {', '.join(scenarios())}")
    writable_folder(args.out)
    for name in names:
        try:
            print(f"wrote {export(name, args.out)}")
        except FileNotFoundError as error:
            print(f"error: {error}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
