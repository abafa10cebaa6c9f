"""Build FMUs and validate them: this project's, or your own script written with fmukit.

    python -m fmukit.build                          # every FMU of the project, into fmus/
    python -m fmukit.build ship                     # only some
    python -m fmukit.build my_autopilot.py --out DIR   # your script -> DIR/<model_name>.fmu

The project's FMUs are Python (``fmubuild.packaging``) and one in C
(``fmubuild.cbuild``), which needs a C compiler: without one it is skipped, with a
note, and the rest is built. A script's FMU carries what it imports of fmukit, and the
modules or packages given with --include, in its resources; the host needs Python
with numpy (``fmubuild.packaging``). Its FMU is
named after its slave's model_name and written beside the script unless --out says
where. docs/own_autopilot.md walks through writing one.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .cbuild import NoCompiler, build_c
from .packaging import build, build_script
from .project import C_FMUS, FMU_DIR, FMUS


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fmukit.build",
                                     description=__doc__.split("\n\n")[0],
                                     epilog="\n\n".join(__doc__.split("\n\n")[1:]),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    project = [*FMUS, *C_FMUS]
    parser.add_argument("names", nargs="*", metavar="NAME|SCRIPT.py",
                        help=f"FMUs of the project (default: all of {', '.join(project)}), or "
                             "paths of your own scripts")
    parser.add_argument("--out", "--dest", dest="out", type=Path,
                        help=f"output folder (default: {FMU_DIR} for the project's FMUs, the "
                             "script's folder for a script)")
    parser.add_argument("--include", action="append", type=Path, default=[], metavar="PATH",
                        help="a module or package a script imports besides fmukit; repeatable")
    args = parser.parse_intermixed_args(argv)
    for name in args.names:
        if name not in project and not name.endswith(".py"):
            parser.error(f"{name!r} is neither an FMU of the project ({', '.join(project)}) "
                         "nor a Python script (.py)")
    for name in args.names or project:
        try:
            if name in FMUS:
                fmu = build(name, args.out or FMU_DIR)
            elif name in C_FMUS:
                fmu = build_c(name, args.out or FMU_DIR)
            else:
                script = Path(name)
                fmu = build_script(script, ("fmukit", *args.include),
                                   args.out or script.resolve().parent)
        except NoCompiler as missing:
            print(f"note: {missing}", file=sys.stderr)
            continue
        except (ValueError, RuntimeError) as error:
            print(f"error: {error}", file=sys.stderr)
            return 1
        print(f"built and validated {fmu}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
