"""Export a scenario as a self-contained SSP package for other FMI tools.

    python -m cosim.export calm_pd                 -> results/ssp/calm_pd.ssp
    python -m cosim.export --all --out DIR         -> the paper's four scenarios
    python -m cosim.export waves_pd --autopilot my.fmu   -> results/ssp/waves_pd-my.ssp

The package is a zip holding SystemStructure.ssd (components, connections, the
scenario's parameter values, the fixed step as an OSP annotation) and
resources/<fmu>.fmu for every FMU it uses (``cosim.interop.ssp``). OSP libcosim,
ecos, fmpy and OMSimulator load it unchanged (see README, "Using the FMUs elsewhere").
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import scenarios
from ._cli import (add_autopilot_options, checked_autopilot, chosen_scenarios, entry, say_error,
                   writable_folder)
from .core.files import OutputError
from .interop.ssp import export


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.export",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("scenario", nargs="?",
                        help=f"one of: {', '.join(scenarios.names())}; or a path to a .ssd file")
    parser.add_argument("--all", action="store_true", help="the paper's four scenarios")
    parser.add_argument("--out", type=Path, default=Path("results/ssp"), help="output folder")
    add_autopilot_options(parser, "the package carries the FMU; with --all, in each of the "
                                  "four scenarios")
    args = parser.parse_args(argv)
    names = chosen_scenarios(parser, args.scenario, args.all)
    if not checked_autopilot(parser, args):
        return 2
    writable_folder(args.out)
    for name in names:
        try:
            print(f"wrote {export(name, args.out, None, args.autopilot, dict(args.map), args.name)}")
        except (ValueError, FileNotFoundError) as error:
            say_error(error)
            return 2
        except OutputError as error:
            say_error(error)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
