"""Benchmarks that print figures (no timed assertions in the tests).

    python -m cosim.bench                 engines side by side, calm_pd and waves_pd, 400 s
    python -m cosim.bench overhead        the masters' own work, with the ship's step idle
    python -m cosim.bench memory          a 24 h run of calm_pd streamed to disk: peak memory
    python -m cosim.bench sweep           runs per second of a sweep: FMI and in-process
                                          backends, 1 and 2 workers

The default benchmark measures, for each scenario, (a) the plain Python modules
wired by hand (cosim.studies.direct), our master (b) on its in-process backend and
(c) through the FMUs, (d) OSP libcosim and (e) ecos on the exported SSP package of the
same scenario, timed in turn round after round (the median of each), and (f) the
floor of any FMI route: (a) plus the FMI calls per step times the measured cost of
one call. One table per scenario, with the ratios.
"""
from __future__ import annotations

import argparse
import sys

from ._cli import entry, say_error
from .studies import bench, bench_sweep


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.bench", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5, help="runs per median (default 5)")
    commands = parser.add_subparsers(dest="command")
    repeats = argparse.ArgumentParser(add_help=False)       # also after the subcommand
    repeats.add_argument("--repeats", type=int, default=argparse.SUPPRESS,
                         help="runs per median (default 5)")
    commands.add_parser("engines", parents=[repeats], help="engines side by side (the default)")
    commands.add_parser("overhead", parents=[repeats],
                        help="what the routes do besides the models (the ship's step idle)")
    mem = commands.add_parser("memory", help="peak memory of a long run streamed to disk, "
                                             "both backends")
    mem.add_argument("--hours", type=float, default=24.0, help="simulated hours (default 24)")
    sweep = commands.add_parser("sweep", help="runs per second of a sweep, both backends, with 1 "
                                             "and 2 workers")
    sweep.add_argument("--runs", type=int, default=16, help="runs per measurement (even)")
    args = parser.parse_args(argv)
    try:
        if args.command == "memory":
            bench.memory(args.hours)
        elif args.command == "sweep":
            bench_sweep.sweep_throughput(args.runs)
        elif args.command == "overhead":
            bench.overhead(args.repeats)
        else:
            bench.engines(args.repeats)
    except (RuntimeError, ValueError, FileNotFoundError) as error:   # e.g. stale FMUs
        say_error(error)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
