"""Export a scenario as a self-contained SSP package for other FMI tools.

Beside the package, a folder for OSP (``cosim.interop.ssp``, docs/interop.md); what another
tool would not apply (a String value, FMI 3.0 FMUs) is said."""
import argparse
import sys
from pathlib import Path

from . import scenarios
from ._cli import add_fmu_options, chosen_scenarios, entry, say_error, writable_folder
from .core.files import OutputError
from .interop.ssp import FMI2_ONLY, described, export, unapplied_strings


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.export",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("scenario", nargs="?",
                        help=f"one of: {', '.join(scenarios.names())}; or a path to a .ssd file")
    parser.add_argument("--all", action="store_true", help="the paper's four scenarios")
    parser.add_argument("--out", type=Path,
                        help="output folder (default: results/ssp, or results/ssp/fmi3 with "
                             "--fmi 3)")
    add_fmu_options(parser, "the package carries the FMU; with --all, in each of the four "
                            "scenarios")
    args = parser.parse_args(argv)
    names = chosen_scenarios(parser, args)
    out = args.out or Path("results/ssp") / ("fmi3" if args.fmi == 3 else "")
    writable_folder(out)
    for name in names:
        try:
            package = export(name, out, None, args.autopilot, dict(args.map), args.name, args.fmi)
            print(f"wrote {package} and {package.with_suffix('')}/")
            newer = sorted({d.fmiVersion for d in described(package)[1].values()} - {"2.0"})
            if newer:
                print(f"note: {package.name} holds FMI {' and '.join(newer)} FMUs: ecos and "
                      f"OMSimulator run it; {' and '.join(FMI2_ONLY.values())} run FMI 2.0 "
                      "FMUs only and cannot", file=sys.stderr)
            for variable, (value, default) in unapplied_strings(package).items():
                print(f"warning: {package.name} sets the String {variable} = {value!r}; "
                      f"OMSimulator and fmpy's SSP runner apply no String binding and "
                      f"would run with its default {default!r}", file=sys.stderr)
        except (ValueError, FileNotFoundError, OutputError) as error:
            say_error(error)
            return 1 if isinstance(error, OutputError) else 2
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
