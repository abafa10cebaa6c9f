"""FMI cross-check reference files for every FMU, in the fmi-cross-check layout.

    python -m fmubuild.crosscheck        # writes fmus/crosscheck/2.0/cs/linux64/...

For each FMU: <name>_in.csv (inputs), <name>_ref.csv (reference outputs),
<name>_ref.opt (start, stop, step, tolerance), ReadMe.txt, and a copy of the FMU
(not kept in git). The references are simulated with fmpy from the built FMU and
committed: tests/test_crosscheck.py replays every FMU with ``fmpy simulate`` and
compares, so they catch both a broken FMI layer and any change of behaviour.
Regenerate them, and say why in the commit, when a change of results is intended.
"""
from __future__ import annotations

import argparse
import csv
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from .project import FMU_DIR

TOOL, VERSION = "ship_autopilot_cosim", "0.1.0"
CROSSCHECK_DIR = FMU_DIR / "crosscheck" / "2.0" / "cs" / "linux64" / TOOL / VERSION


@dataclass(frozen=True)
class Case:
    stop: float
    inputs: tuple[str, ...]
    table: tuple[tuple[float, ...], ...]     # rows of (time, *inputs), linearly interpolated
    step: float = 0.1
    rel_tol: float = 1e-9


CASES = {
    "ship": Case(60.0, ("delta_c", "n1", "n2", "n3"),
                 ((0, 0.0, 8.13, 8.13, 0.0), (5, 0.0, 8.13, 8.13, 0.0),
                  (5, 0.35, 8.13, 8.13, 0.0), (25, 0.35, 8.13, 8.13, 0.0),
                  (25, -0.2, 6.0, 7.0, 2.0), (45, -0.2, 6.0, 7.0, 2.0),
                  (60, 0.1, 8.13, 8.13, -2.0))),
    "pd_autopilot": Case(30.0, ("psi", "r", "psi_d"),
                         ((0, 0.0, 0.0, 0.0), (10, 0.2, 0.01, 0.7), (20, 0.6, 0.004, 0.7),
                          (20, 0.6, 0.004, -3.0), (30, 3.1, -0.01, -3.0))),
    "pid_autopilot": Case(30.0, ("psi", "r", "psi_d"),
                          ((0, 0.0, 0.0, 0.0), (10, 0.2, 0.01, 0.7), (20, 0.6, 0.004, 0.7),
                           (20, 0.6, 0.004, -3.0), (30, 3.1, -0.01, -3.0))),
    "smc_autopilot": Case(60.0, ("psi", "r", "psi_d"),
                          ((0, 0.0, 0.0, 0.0), (10, 0.0, 0.0, 0.7), (40, 0.5, 0.005, 0.7),
                           (40, 0.5, 0.005, 0.0), (60, 0.3, -0.005, 0.0))),
    "guidance": Case(400.0, ("x", "y"), ((0, 0, 0), (100, 30.2, 0.3), (200, 61, 24),
                                         (300, 95, 25), (400, 150, -10))),
    "manoeuvre": Case(60.0, ("psi",), ((0, 0.0), (20, -0.5), (40, 0.5), (60, -0.5))),
}


def files(name: str) -> dict[str, Path]:
    folder = CROSSCHECK_DIR / name
    return {"dir": folder, "fmu": folder / f"{name}.fmu", "in": folder / f"{name}_in.csv",
            "ref": folder / f"{name}_ref.csv", "opt": folder / f"{name}_ref.opt"}


def read_opt(path: Path) -> dict[str, float]:
    """The key, value pairs of a _ref.opt file."""
    pairs = (line.split(",", 1) for line in path.read_text().splitlines() if "," in line)
    return {key.strip(): float(value) for key, value in pairs}


def generate(name: str) -> Path:
    """Write the cross-check files of one FMU from the built fmus/<name>.fmu."""
    from fmpy import simulate_fmu
    from fmpy.util import read_csv, write_csv

    case, paths = CASES[name], files(name)
    paths["dir"].mkdir(parents=True, exist_ok=True)
    shutil.copy2(FMU_DIR / f"{name}.fmu", paths["fmu"])
    with open(paths["in"], "w", newline="") as f:
        writer = csv.writer(f, quoting=csv.QUOTE_NONNUMERIC)
        writer.writerow(["time", *case.inputs])
        writer.writerows([float(v) for v in row] for row in case.table)
    paths["opt"].write_text(f"StartTime, 0.0\nStopTime, {case.stop!r}\nStepSize, {case.step!r}\n"
                            f"RelTol, {case.rel_tol!r}\n")
    result = simulate_fmu(str(paths["fmu"]), start_time=0.0, stop_time=case.stop,
                          step_size=case.step, output_interval=case.step,
                          input=read_csv(str(paths["in"])))
    write_csv(str(paths["ref"]), result)
    (paths["dir"] / "ReadMe.txt").write_text(
        f"{name}.fmu, FMI 2.0 co-simulation, built with pythonfmu 0.7.0 by {TOOL} {VERSION}.\n"
        f"Reference simulated with fmpy: fixed communication step {case.step} s, inputs "
        f"linearly interpolated from {name}_in.csv, default parameters.\n"
        "The FMU needs Python >= 3.10 with numpy on the host (see the project README).\n")
    return paths["dir"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fmubuild.crosscheck",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="NAME", help=f"FMUs (default: all of "
                                                                  f"{', '.join(CASES)})")
    args = parser.parse_args(argv)
    for name in args.names or CASES:
        if name not in CASES:
            parser.error(f"unknown FMU {name!r}; known: {', '.join(CASES)}")
        print(f"wrote {generate(name)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
