"""Run a scenario of the Tomera (2010) study as an FMI co-simulation.

Examples:
  python -m cosim.run calm_pd                  the PD autopilot on the route, calm water
  python -m cosim.run waves_smc --out /tmp/w   the sliding-mode autopilot in waves
  python -m cosim.run calm_pd --set ship.Hs=0.003 --set autopilot.Kd=30
  python -m cosim.run --all                    the paper's four runs, Tables 1-2
  python -m cosim.run --all --spread           ... and how far one last bit moves each figure
  python -m cosim.run waves_pd --autopilot my.fmu   your own autopilot in waves_pd's place
  python -m cosim.run waves_pd --autopilot my.fmu --isolate   ... each FMU in a process of its own
  python -m cosim.run --all --fmi 3            the same runs through the FMI 3.0 twins
  python -m cosim.run waves_pd --events gear_failure   the steering gear fails at 150 s

A scenario is an SSP system structure file (cosim/scenarios/*.ssd). A run writes every
signal at every 0.1 s step to SCENARIO.csv and a figure like the paper's Figs 2-3 to
SCENARIO.png, and prints the cost of eq (19) (or the manoeuvre's figures).
"""
import argparse
import dataclasses
import shutil
import sys
from pathlib import Path

from tqdm import tqdm

from . import scenarios
from ._cli import (add_fmu_options, add_isolation_options, chosen_scenarios, entry, isolation,
                   leave, number_option, positive_seconds, say_error, say_note, setting_option,
                   writable_folder)
from .analysis.metrics import LAMBDA, Cost
from .analysis.reports import conditions, headline, tables
from .api import overrides_of
from .core.wiring import COUPLINGS
from .core.files import FolderBusy, OutputError
from .core.instance import FmuCallError
from .core.interrupt import StopSignals
from .core.master import BACKENDS
from .core.ssd import SystemDescription
from .core.watchdog import STEP_LIMIT_S, Limits
from .outputs import Options, run_and_write
from .scenarios.autopilot import COMPONENT
from .studies.cpu_variants import PERTURBED, spread


def video_format() -> str:
    """'mp4' where ffmpeg is installed, else 'gif'."""
    return "mp4" if shutil.which("ffmpeg") else "gif"


def run_scenario(system: SystemDescription, label: str, out: Path, overrides: dict,
                 options: Options) -> tuple[int, Cost | None]:
    """Simulate one system, write its outputs as ``label`` and print its report; the status
    0, 1 if an FMU failed, 130 / 143 if Ctrl-C or SIGTERM stopped it (its rows written)."""
    # a bar on standard error for runs longer than a second, on a terminal only
    with StopSignals() as stop, tqdm(desc=label, unit="step", delay=1.0, leave=False,
                                     file=sys.stderr, disable=None) as bar:
        def progress(k: int, n: int) -> None:
            bar.total = n
            bar.update(k - bar.n)
        outcome = run_and_write(system, label, out, overrides, options, progress, stop,
                                notes=say_note)
    recording, csv_path = outcome.recording, outcome.csv
    print("\n  ".join([headline(label, recording.meta), *conditions(recording.meta)]))
    if recording.interrupted:
        print(f"{recording.error}; written to {csv_path}, with its metadata", file=sys.stderr)
    elif recording.error:
        print(f"error: {recording.error}", file=sys.stderr)
        if outcome.written:
            print(f"  the {recording.rows} rows recorded before the error are in {csv_path}",
                  file=sys.stderr)
        else:
            print(f"  nothing was computed, so nothing was written: the earlier outputs of "
                  f"{label} in {out}, if any, are as they were", file=sys.stderr)
    elif options.stream:
        print(f"  {recording.rows} rows streamed to {csv_path} "
              "(no report or figure in --stream mode)")
    else:
        for line in outcome.report:
            print(f"  {line}")
        print(f"  wrote {', '.join(str(p) for p in outcome.written)}")
    if outcome.late_signal:
        print(f"interrupted by {stop.received.name} after the last step; the outputs above "
              "are complete", file=sys.stderr)
    return outcome.status, outcome.cost


def main(argv: list[str] | None = None) -> int:
    description, _, epilog = __doc__.partition("\n\n")
    parser = argparse.ArgumentParser(prog="python -m cosim.run", description=description,
                                     epilog=epilog,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenario", nargs="?",
                        help=f"one of: {', '.join(scenarios.names())}; or a path to a .ssd file")
    parser.add_argument("--all", action="store_true",
                        help="run the paper's four scenarios, print Tables 1-2 beside the paper's")
    parser.add_argument("--out", type=Path,
                        help="output folder (default: results/SCENARIO, or results/ with --all)")
    parser.add_argument("--stop-time", type=number_option, metavar="T",
                        help="end of the run in s (default: the scenario's, 400 s)")
    parser.add_argument("--set", action="append", default=[], type=setting_option,
                        metavar="FMU.VAR=VALUE",
                        help="override a parameter, e.g. ship.Hs=0.01 (SI units, radians; or with a "
                             "unit it takes: ship.psi0=40deg, ship.u0=0.3m/s); "
                             "repeatable")
    parser.add_argument("--events", metavar="NAME|FILE",
                        help="timed events: one of "
                             f"{', '.join(scenarios.event_names())}, or an OSP scenario "
                             "file (.json); docs/running.md")
    parser.add_argument("--coupling", choices=COUPLINGS, default="gauss-seidel",
                        help="gauss-seidel: along the signal flow, as the paper's Simulink "
                             "model (default); jacobi: all FMUs on the previous step's outputs")
    parser.add_argument("--lambda", dest="lam", type=number_option, default=LAMBDA,
                        help=f"weight of eq (19) (default {LAMBDA:.4f}, calibrated on calm_pd)")
    parser.add_argument("--backend", choices=BACKENDS, default="fmi",
                        help="fmi: load the FMUs through FMI (default); inprocess: call their "
                             "Python classes, the same results bit for bit (an FMU not built "
                             "from this checkout's sources runs through FMI, with a note)")
    add_fmu_options(parser, "with --all it also runs in calm_pd's and waves_pd's place, as an "
                            "extra row of Tables 1-2")
    parser.add_argument("--no-plot", action="store_true", help="skip the figure")
    parser.add_argument("--figure-format", action="append", default=[], choices=("svg", "pdf"),
                        help="also write the figure as SVG or PDF (for papers); repeatable")
    parser.add_argument("--animate", nargs="?", const=video_format(), choices=("gif", "mp4"),
                        help="also write an animation of the ship along its track: "
                             f"SCENARIO.gif, or .mp4 where ffmpeg is installed (here: "
                             f"{video_format()})")
    parser.add_argument("--spread", nargs="?", type=int, const=20, metavar="ULPS",
                        help="also run each course-keeping scenario with "
                             f"{' and then '.join('.'.join(p) for p in PERTURBED)} moved by "
                             "1 ... ULPS units in the last place either way (20 if not "
                             "given) and print how far that moves psi_E, delta_E and J")
    parser.add_argument("--stream", action="store_true",
                        help="write rows to the CSV in chunks as the run goes: flat memory "
                             "for long runs; no report or figure")
    parser.add_argument("--step-timeout", type=positive_seconds, default=STEP_LIMIT_S, metavar="S",
                        help="end the run with an error if one step of the FMUs (or their "
                             f"instantiation) takes over S s of wall-clock time (default "
                             f"{STEP_LIMIT_S:g})")
    parser.add_argument("--run-timeout", type=positive_seconds, metavar="S",
                        help="end the run with an error, keeping its rows, after S s of "
                             "wall-clock time (default: no limit)")
    add_isolation_options(parser, "none")
    args = parser.parse_args(argv)
    names = chosen_scenarios(parser, args)
    try:
        overrides = overrides_of(args.set)
    except ValueError as error:             # a variable set twice
        parser.error(str(error))
    if args.spread is not None and args.spread < 1:
        parser.error(f"--spread takes a number of ulps >= 1, got {args.spread}")
    for option, needs in (("animate", "the run in memory"), ("spread", "each run's report")):
        if getattr(args, option) and args.stream:
            parser.error(f"--{option} needs {needs}; it cannot be combined with --stream")
    if args.animate == "mp4" and video_format() != "mp4":
        parser.error("--animate mp4 needs ffmpeg, which is not installed here; use gif")
    options = Options(args.coupling, args.stop_time, args.lam, args.backend,
                      not args.no_plot, ("png", *args.figure_format), args.stream, args.animate,
                      Limits(args.step_timeout, args.run_timeout), isolation(parser, args))
    # (scenario, autopilot, row of Tables 1-2): with --all and --autopilot, the user's
    # autopilot also in calm_pd's and waves_pd's place
    runs = [(s, None, tuple(s.split("_"))) for s in names] if args.all else \
        [(names[0], args.autopilot, None)]
    if args.all and args.autopilot:
        runs += [(s, args.autopilot, (s.split("_")[0], args.name or args.autopilot.stem))
                 for s in ("calm_pd", "waves_pd")]
    status, costs, spreads, count = 0, {}, {}, 0
    perturbed = ", ".join(".".join(p) for p in PERTURBED)
    for scenario, autopilot, table_row in runs:
        try:
            label = scenarios.label(scenario, autopilot, args.name)
        except ValueError as error:         # a name from a file name that is no plain name
            parser.error(str(error))
        out = args.out / label if args.all and args.out else args.out or Path("results") / label
        # with --all, autopilot.* settings are for the user's autopilot, not the paper's
        settings = {c: v for c, v in overrides.items()
                    if c != COMPONENT or autopilot or not args.autopilot}
        created = not out.exists()
        writable_folder(out)
        try:
            system = scenarios.load(scenario, autopilot, dict(args.map), args.name, args.fmi)
            if args.events:
                system = dataclasses.replace(system, events=scenarios.events(args.events))
            code, result = run_scenario(system, label, out, settings, options)
        except (ValueError, FileNotFoundError, FmuCallError, FolderBusy, OutputError) as error:
            say_error(error)
            if created and not any(out.iterdir()):
                out.rmdir()                     # nothing was run: leave nothing behind
            return 1 if isinstance(error, OutputError) else 2
        status = max(status, code)
        if code > 128:                          # interrupted: no further run
            return code
        if result is not None and args.spread:
            try:
                ensemble = spread(system, settings, args.spread, args.lam, args.coupling,
                                  args.stop_time)
            except (ValueError, RuntimeError) as error:
                print(f"error: {error}", file=sys.stderr)
                status = max(status, 1)
            else:
                print(f"  last-bit spread over {ensemble.runs} runs ({perturbed} moved by up "
                      f"to {args.spread} ulp): {ensemble.describe()}")
                spreads[table_row], count = ensemble.describe(), ensemble.runs
        if result is not None and table_row is not None:
            costs[table_row] = result
    if args.all and costs:
        title = (f"How far one last bit moves each figure (the largest change over {count} "
                 f"runs, {perturbed} moved by up to {args.spread} ulp; where it shows at the "
                 "printed digits)")
        print("\n" + tables(costs, spreads, title))
    return status


if __name__ == "__main__":
    leave(entry(main))
