"""FMI cross-check reference files of every Python FMU and its FMI 3.0 twin (docs/interop.md),
simulated by fmpy; regenerate them, saying why in the commit, only when results change.

    python -m fmubuild.crosscheck            # both versions: fmus/crosscheck/2.0/..., 3.0/...
    python -m fmubuild.crosscheck --fmi 3    # only the FMI 3.0 twins (fmus/fmi3/)"""
from __future__ import annotations

import argparse
import csv
import shutil
import subprocess
import sys
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path

from cosim.core.files import fresh_folder

from .project import FMU_DIR, FMU_DIRS, ROUTES

TOOL, VERSION = "ship_autopilot_cosim", "0.1.0"
CROSSCHECK_DIRS = {fmi: FMU_DIR / "crosscheck" / f"{fmi}.0" / "cs" / route.linux / TOOL / VERSION
                   for fmi, route in ROUTES.items()}     # the references are made on Linux


@dataclass(frozen=True)
class Case:
    stop: float                              # s
    inputs: tuple[str, ...]
    table: tuple[tuple[float, ...], ...]     # rows of (time, *inputs), linearly interpolated
    step: float = 0.1
    rel_tol: float = 1e-9


_HEADING = Case(30.0, ("psi", "r", "psi_d"),
                ((0, 0.0, 0.0, 0.0), (10, 0.2, 0.01, 0.7), (20, 0.6, 0.004, 0.7),
                 (20, 0.6, 0.004, -3.0), (30, 3.1, -0.01, -3.0)))    # a turn across 180 deg
_ROUTE = Case(400.0, ("x", "y"), ((0, 0, 0), (100, 30.2, 0.3), (200, 61, 24), (300, 95, 25),
                                   (400, 150, -10)))    # along and across the paper's route
CASES = {
    "ship": Case(60.0, ("delta_c", "n1", "n2", "n3"),
                 ((0, 0.0, 8.13, 8.13, 0.0), (5, 0.0, 8.13, 8.13, 0.0),
                  (5, 0.35, 8.13, 8.13, 0.0), (25, 0.35, 8.13, 8.13, 0.0),
                  (25, -0.2, 6.0, 7.0, 2.0), (45, -0.2, 6.0, 7.0, 2.0),
                  (60, 0.1, 8.13, 8.13, -2.0))),
    "pd_autopilot": _HEADING,
    "pid_autopilot": _HEADING,
    "policy_autopilot": _HEADING,
    "smc_autopilot": Case(60.0, ("psi", "r", "psi_d"),
                          ((0, 0.0, 0.0, 0.0), (10, 0.0, 0.0, 0.7), (40, 0.5, 0.005, 0.7),
                           (40, 0.5, 0.005, 0.0), (60, 0.3, -0.005, 0.0))),
    "guidance": _ROUTE,
    "los_guidance": _ROUTE,
    "environment": Case(300.0, (), ((0,), (300,))),    # its defaults: no current, no wind
    "sensors": Case(30.0, ("psi", "r", "x", "y"), ((0, 0.0, 0.0, 0.0, 0.0),
                                                   (30, 0.7, 0.01, 9.0, 1.0))),
    "observer": Case(30.0, ("psi_m", "delta"), ((0, 0.0, 0.0), (10, 0.3, 0.1),
                                                (30, 0.25, -0.1))),
    "manoeuvre": Case(60.0, ("psi",), ((0, 0.0), (20, -0.5), (40, 0.5), (60, -0.5))),
}


def files(name: str, fmi: int = 2) -> dict[str, Path]:
    """The cross-check folder of FMU ``name``'s FMI ``fmi`` twin and its files."""
    folder = CROSSCHECK_DIRS[fmi] / name
    return {"dir": folder, "fmu": folder / f"{name}.fmu", "in": folder / f"{name}_in.csv",
            "ref": folder / f"{name}_ref.csv", "opt": folder / f"{name}_ref.opt"}


def generate(name: str, fmi: int = 2) -> Path:
    """The cross-check folder of ``FMU_DIRS[fmi]/<name>.fmu``, written again whole."""
    case, paths = CASES[name], files(name, fmi)
    paths["dir"].parent.mkdir(parents=True, exist_ok=True)
    with fresh_folder(paths["dir"]) as folder:
        fmu, inputs, ref, opt = (folder / paths[key].name for key in ("fmu", "in", "ref", "opt"))
        shutil.copy2(FMU_DIRS[fmi] / f"{name}.fmu", fmu)
        with open(inputs, "w", newline="") as f:
            writer = csv.writer(f, quoting=csv.QUOTE_NONNUMERIC)
            writer.writerow(["time", *case.inputs])
            writer.writerows([float(v) for v in row] for row in case.table)
        opt.write_text(f"StartTime, 0.0\nStopTime, {case.stop!r}\nStepSize, {case.step!r}\n"
                       f"RelTol, {case.rel_tol!r}\n")
        simulated = subprocess.run(
            [sys.executable, "-I", "-m", "fmpy.cli", "simulate", str(fmu), "--start-time", "0.0",
             "--stop-time", repr(case.stop), "--step-size", repr(case.step), "--output-interval",
             repr(case.step), "--input-file", str(inputs), "--output-file", str(ref)],
            capture_output=True, text=True, timeout=300)
        if simulated.returncode != 0:
            raise RuntimeError(f"fmpy could not simulate {FMU_DIRS[fmi] / name}.fmu "
                               f"(exit status {simulated.returncode}):\n{simulated.stderr}")
        builder = ROUTES[fmi].pythonfmu
        (folder / "ReadMe.txt").write_text(
            f"{name}.fmu, FMI {fmi}.0 co-simulation, built with {builder} {version(builder)} "
            f"by {TOOL} {VERSION}.\n"
            f"Reference simulated with fmpy: fixed communication step {case.step} s, inputs "
            f"linearly interpolated from {name}_in.csv, default parameters.\n"
            "The FMU needs Python >= 3.10 with numpy on the host (see the project README).\n")
    return paths["dir"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fmubuild.crosscheck",
                                     description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("names", nargs="*", metavar="NAME",
                        help=f"FMUs (default: all of {', '.join(CASES)})")
    parser.add_argument("--fmi", type=int, choices=sorted(CROSSCHECK_DIRS),
                        help="only the FMUs of this FMI version (default: both, FMI 2.0's "
                             f"from {FMU_DIRS[2]}, FMI 3.0's from {FMU_DIRS[3]})")
    args = parser.parse_args(argv)
    for name in args.names:
        if name not in CASES:
            parser.error(f"unknown FMU {name!r}; known: {', '.join(CASES)}")
    for fmi in [args.fmi] if args.fmi else sorted(CROSSCHECK_DIRS):
        for name in args.names or CASES:
            print(f"wrote {generate(name, fmi)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
