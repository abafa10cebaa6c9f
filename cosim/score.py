"""Score your autopilot against the paper's PD and sliding-mode autopilots and the PID.

Runs the paper's route in calm water and waves, a 40 deg course change, and three N-seed
ensembles (the paper's waves; wind and current; a steering-gear pump failure) on Dask, for
your FMU and the three project autopilots, and scores each on every criterion on its own
(docs/own_autopilot.md). Writes scorecard.md and its figures to results/score/NAME/ and
prints it. Given result files (.csv) of a run from any FMI tool instead, prints that run's
value of every criterion.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from tqdm import tqdm

from autopilot_fmu.guidance import PAPER_ROUTE, R_ACCEPT
from ship_fmu.steering_gear import DELTA_MAX

from ._cli import (add_isolation_options, add_port_options, checked_autopilot, count, entry,
                   isolation, say_error, say_note, setting_option, writable_folder)
from . import scenarios
from .analysis.results import read_results
from .api import overrides_of
from .core.files import FolderBusy, OutputError
from .studies.scorecard import BASELINES, SEAS, backend_notes, score
from .studies.scorecard_report import result_card
from .studies.cluster import NoWorkers, SweepError
from .studies.sweep_spec import MAX_RUNS
from .studies.sweep_task import SWEEP_BACKENDS


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.score",
                                     description=__doc__.split("\n\n")[0],
                                     epilog="\n\n".join(__doc__.split("\n\n")[1:]),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("autopilot", type=Path, metavar="FMU|CSV", nargs="+",
                        help="your autopilot: FMI 2.0 co-simulation, inputs psi (rad), r "
                             "(rad/s), psi_d (rad), output delta_c (rad); or a run's result "
                             "files: OMSimulator's or fmpy's CSV, or libcosim's one per "
                             "component")
    parser.add_argument("--route", default=PAPER_ROUTE, metavar="X,Y;X,Y;...",
                        help="with result files: the route their guidance followed, m "
                             "(default: the paper's)")
    parser.add_argument("--R-accept", dest="R_accept", type=float, default=R_ACCEPT,
                        metavar="M", help=f"with result files: the circle of acceptance, m "
                                          f"(default {R_ACCEPT:g})")
    add_port_options(parser)
    parser.add_argument("--set", action="append", default=[], type=setting_option,
                        metavar="autopilot.VAR=VALUE",
                        help="a parameter of your autopilot, e.g. autopilot.Kp=1.5; "
                             "repeatable (the ship, sea and route stay the paper's, the same "
                             "for every contender)")
    parser.add_argument("--seeds", type=int, default=20, help="wave seeds of each ensemble "
                                                              "(default 20)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run the ensembles on this Dask scheduler (default: a local "
                             "cluster)")
    parser.add_argument("--workers", type=count, help="local Dask worker processes "
                                                    "(default: one per core)")
    parser.add_argument("--backend", choices=SWEEP_BACKENDS, default="fmi",
                        help="fmi: every run through the FMUs (default); inprocess: this "
                             "project's FMUs as Python classes, the same results; batch: the "
                             "single runs in-process, the ensembles' stepped together as "
                             "arrays, the same results again. An FMU that cannot run so is "
                             "noted before the scorecard starts")
    parser.add_argument("--out", type=Path, help="output folder (default: results/score/NAME)")
    add_isolation_options(parser, "foreign")
    args = parser.parse_args(argv)
    if all(path.suffix.lower() == ".csv" for path in args.autopilot):
        try:
            print(result_card(read_results(args.autopilot, {
                "guidance": {"waypoints": args.route, "R_accept": args.R_accept},
                "ship": {"delta_max": DELTA_MAX}}), args.autopilot))
        except ValueError as error:
            say_error(error)
            return 2
        return 0
    if len(args.autopilot) > 1:
        parser.error("give one autopilot FMU, or result files (.csv) only")
    args.autopilot = args.autopilot[0]
    isolated = isolation(parser, args)
    try:                                    # every contender has the same components
        isolated.check(scenarios.load("calm_pd").components)
    except ValueError as error:
        parser.error(f"--{error}")
    if not 1 <= args.seeds <= MAX_RUNS // 4:
        parser.error(f"--seeds must be from 1 to {MAX_RUNS // 4} (four contenders, at most "
                     f"{MAX_RUNS} runs an ensemble), got {args.seeds}")
    others = [target for target, _ in args.set if not target.startswith("autopilot.")]
    if others:
        parser.error(f"--set sets your autopilot's parameters (autopilot.NAME=VALUE); "
                     f"{', '.join(others)} would change only your runs' conditions, not the "
                     "others': the comparison would not be fair")
    checked_autopilot(parser, args)
    name = args.name or args.autopilot.stem
    if name in BASELINES:
        parser.error(f"your autopilot's name {name!r} is one of the baselines' "
                     f"({', '.join(BASELINES)}): give another with --name")
    out = writable_folder(args.out or Path("results") / "score" / name)
    for note in backend_notes(args.autopilot.resolve(), name, dict(args.map), args.backend):
        say_note(note)
    started = time.perf_counter()

    def progress(step: str) -> None:
        if bar.n or step != "calm water, PD":
            bar.update()
        bar.set_postfix_str(step)
    try:
        with tqdm(total=4 * 2 + 4 + len(SEAS), desc="scorecard", unit="step", file=sys.stderr,
                  disable=None, bar_format="{desc}: {n}/{total} {bar} {elapsed} {postfix}") as bar:
            overrides_of(args.set)              # refuses a variable set twice
            text = score(args.autopilot.resolve(), name, out, args.seeds, dict(args.map),
                         dict(args.set), args.workers, args.scheduler, progress, args.backend,
                         isolated)
            bar.update()
    except (ValueError, FileNotFoundError, FolderBusy, OutputError,
            SweepError) as error:         # SweepError: a worker runs other code
        say_error(error)
        return 1
    except NoWorkers as stopped:
        print(f"{stopped}: no scorecard written", file=sys.stderr)
        return stopped.exit_status
    print(text)
    print(f"wrote {out / 'scorecard.md'} and its figures in {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
