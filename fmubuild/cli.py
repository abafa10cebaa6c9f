"""Build FMUs and validate them: this project's, or your own script written with fmukit.

    python -m fmukit.build                          # every FMU of the project, into fmus/
    python -m fmukit.build --fmi 3                  # their FMI 3.0 twins, into fmus/fmi3/
    python -m fmukit.build ship                     # only some
    python -m fmukit.build my_autopilot.py --out DIR   # your script -> DIR/<model_name>.fmu

The C FMU needs a C compiler (else it is skipped, with a note). A script's FMU carries what
it imports of fmukit and what --include names. See docs/own_autopilot.md.
"""
from __future__ import annotations

import argparse
import os
import sys
import traceback
from importlib.machinery import PathFinder
from pathlib import Path

from .cbuild import NoCompiler, build_c
from .packaging import build, build_script, imports
from .project import C_FMUS, FMU_DIRS, FMUS, ROOT, ROUTES


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fmukit.build",
                                     description=__doc__.split("\n\n")[0],
                                     epilog="\n\n".join(__doc__.split("\n\n")[1:]),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    project = {**dict.fromkeys(FMUS, build), **dict.fromkeys(C_FMUS, build_c)}   # name: builder
    parser.add_argument("names", nargs="*", metavar="NAME|SCRIPT.py",
                        help=f"FMUs of the project (default: all of {', '.join(project)}), or "
                             "paths of your own scripts")
    parser.add_argument("--out", "--dest", dest="out", type=Path,
                        help=f"output folder (default: {FMU_DIRS[2]} for the project's FMUs, "
                             f"{FMU_DIRS[3]} for their FMI 3.0 twins, the script's folder for "
                             "a script, its folder fmi3 for its FMI 3.0 FMU)")
    parser.add_argument("--include", action="append", type=Path, default=[], metavar="PATH",
                        help="a module or package a script imports besides fmukit; repeatable")
    parser.add_argument("--fmi", type=int, choices=sorted(ROUTES), default=2,
                        help="the FMI version to build: 2 (2.0, the default) or 3 (3.0)")
    args = parser.parse_intermixed_args(argv)
    for name in args.names:
        if name not in project and not name.endswith(".py"):
            parser.error(f"{name!r} is neither an FMU of the project ({', '.join(project)}) "
                         "nor a Python script (.py)")
    for name in args.names or project:
        try:
            fmu = (project[name](name, args.out, args.fmi) if name in project else
                   _build_script(Path(name), args.include, args.out, args.fmi))
        except NoCompiler as missing:
            print(f"note: {missing}", file=sys.stderr)
            continue
        except (ValueError, RuntimeError) as error:
            print(f"error: {error}", file=sys.stderr)
            return 1
        print(f"built and validated {fmu}")
    return 0


def _build_script(script: Path, includes: list[Path], out: Path | None, fmi: int) -> Path:
    """A user's script built into ``out``; ValueError naming what is missing or uncarried."""
    if not script.is_file():
        raise ValueError(f"{script} does not exist")
    for include in includes:
        if not include.exists():
            raise ValueError(f"{include}, to be carried by {script.name}'s FMU, does not exist")
    if uncarried := _uncarried(script, includes):
        raise ValueError(uncarried)
    try:
        return build_script(script, ("fmukit", *includes),
                            out or script.resolve().parent / ("fmi3" if fmi == 3 else ""), fmi=fmi)
    except SystemExit as exit_:
        frames = [f for f in traceback.extract_tb(exit_.__traceback__)
                  if Path(f.filename).name == script.name]      # the innermost in the script
        site = f"{script}:{frames[-1].lineno}" if frames else f"{script}, or a module it imports,"
        raise ValueError(f"cannot build an FMU from {script}: {site} called "
                         f"sys.exit({exit_.code!r}) when imported; a slave script must only "
                         "define its classes (move a test run under "
                         "'if __name__ == \"__main__\":')") from None


def _uncarried(script: Path, includes: list[Path]) -> str | None:
    """What to do about the modules ``script`` or ``includes`` need that a host lacks, or None."""
    provided = {"fmukit", *(p.stem if p.is_file() else p.name for p in includes)}
    local = [script.resolve().parent, Path.cwd().resolve(), ROOT,
             *(p.resolve().parent for p in includes)]
    host = [p for p in sys.path if p and Path(p).exists() and Path(p).resolve() not in local]
    files = [f for p in includes for f in ([p] if p.is_file() else sorted(p.rglob("*.py")))]
    missing: dict[str, tuple[Path, Path | None]] = {}       # module: its importer, where
    for file in [script, *(f for f in files if f.suffix == ".py")]:
        for module in dict.fromkeys(m.split(".")[0] for m, optional in imports(file)
                                    if not optional):
            if module in {*provided, *missing, *sys.stdlib_module_names} \
                    or PathFinder.find_spec(module, host):
                continue
            spec = PathFinder.find_spec(module, [str(folder) for folder in local])
            where = spec and (spec.submodule_search_locations or [spec.origin])  # a package's
            missing[module] = (file, Path(next(iter(where))) if where else None)
    if not missing:
        return None
    one = len(missing) == 1
    lines = [(f"cannot build an FMU from {script}: {'a module' if one else 'modules'} it "
              "imports would not be in the FMU, and a host has only the FMU:")]
    for module, (importer, found) in missing.items():
        where = (f"found at {_shown(found)}" if found else
                 "found neither here nor among the packages installed in this Python: "
                 "pip install it, if it is a package")
        lines.append(f"  {_shown(importer)} imports {module} ({where})")
    command = ["python -m fmukit.build", _shown(script),
               *(f"--include {_shown(p)}" for p in includes),
               *(f"--include {_shown(found) if found else f'PATH/TO/{module}.py'}"
                 for module, (_, found) in missing.items())]
    lines.append(f"carry {'it' if one else 'them'} with --include "
                 f"(a module's file or a package's folder):\n  {' '.join(command)}")
    return "\n".join(lines)


def _shown(path: Path) -> str:
    absolute = Path(path).resolve()
    return os.path.relpath(absolute) if Path.cwd().resolve() in absolute.parents else str(absolute)


if __name__ == "__main__":
    sys.exit(main())
