"""Export a scenario as a self-contained SSP package for other FMI tools.

    python -m cosim.export calm_pd                 -> results/ssp/calm_pd.ssp
    python -m cosim.export --all --out DIR         -> the paper's four scenarios
    python -m cosim.export waves_pd --autopilot my.fmu   -> results/ssp/waves_pd-my.ssp

The package is a zip holding SystemStructure.ssd (components, connections, the
scenario's parameter values, the fixed step as OSP's and OpenModelica's annotations)
and resources/<fmu>.fmu for every FMU it uses; beside it, DIR/<label>/ holds OSP's
OspSystemStructure.xml and the FMUs (``cosim.interop.ssp``). OSP libcosim, ecos,
fmpy, OMSimulator and OSP's tools load them unchanged (docs/interop.md). A String
parameter value that OMSimulator and fmpy's SSP runner would not apply is named in a
warning (the guidance's route is written as numbers, which they do apply).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import scenarios
from ._cli import (add_autopilot_options, checked_autopilot, chosen_scenarios, entry, say_error,
                   writable_folder)
from .core.files import OutputError
from .interop.ssp import export, unapplied_strings


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
            package = export(name, args.out, None, args.autopilot, dict(args.map), args.name)
            print(f"wrote {package} and {package.with_suffix('')}/")
            for variable, (value, default) in unapplied_strings(package).items():
                print(f"warning: {package.name} sets the String {variable} = {value!r}; "
                      f"OMSimulator and fmpy's SSP runner apply no String binding and "
                      f"would run with its default {default!r}", file=sys.stderr)
        except (ValueError, FileNotFoundError) as error:
            say_error(error)
            return 2
        except OutputError as error:
            say_error(error)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
