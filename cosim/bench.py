"""Benchmarks that print figures, with the machine and the load (docs/performance.md).

    python -m cosim.bench                 engines side by side, calm_pd and waves_pd, 400 s
    python -m cosim.bench overhead        the masters' own work, with the ship's step idle
    python -m cosim.bench memory          a 24 h run of calm_pd streamed to disk: peak memory
    python -m cosim.bench sweep           sweeps on a local cluster, every backend with 1 and
                                          2 workers; the batch route's goals (--parts)
    python -m cosim.bench rl              the ship's vector env against Gymnasium's sync vector
                                          env of single envs: env steps per second
    python -m cosim.bench all             the five in turn, as docs/performance.md records them
"""
from __future__ import annotations

import argparse
import sys

from ._cli import entry, say_error
from .rl.throughput import throughput
from .studies import sweep_timing, timing

SWEEP_PARTS = ("throughput", "campaign", "memory")
BENCHMARKS = ("engines", "overhead", "memory", "sweep", "rl")


def _counts(text: str) -> tuple[int, ...]:
    """A comma-separated list of whole numbers >= 1."""
    if not all(part.strip().isdecimal() and int(part) >= 1 for part in text.split(",")):
        raise argparse.ArgumentTypeError(f"expected whole numbers >= 1 separated by commas, "
                                         f"got {text!r}")
    return tuple(map(int, text.split(",")))


def _benchmark(name: str, args: argparse.Namespace, repeats: int) -> None:
    if name == "memory":
        timing.memory(args.hours)
    elif name == "sweep":                       # the parts asked for, in their order
        if "throughput" in args.parts:
            seas = ("waves", "calm") if args.sea == "both" else (args.sea,)
            sweep_timing.sweep_throughput(args.runs, args.batch_runs, seas, rounds=args.rounds)
        if "campaign" in args.parts:
            sweep_timing.campaign(args.campaign_runs)
        if "memory" in args.parts:
            sweep_timing.batch_memory(args.memory_members)
    elif name == "rl":
        throughput(args.ships, repeats)
    elif name == "overhead":
        timing.overhead(repeats)
    else:
        timing.engines(repeats)


def main(argv: list[str] | None = None) -> int:
    repeats = argparse.ArgumentParser(add_help=False)       # before or after the subcommand
    repeats.add_argument("--repeats", type=int, default=argparse.SUPPRESS,
                         help="runs per median (default 5)")
    parser = argparse.ArgumentParser(prog="python -m cosim.bench", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     parents=[repeats])
    commands = parser.add_subparsers(dest="command")
    commands.add_parser("engines", parents=[repeats], help="engines side by side (the default)")
    commands.add_parser("overhead", parents=[repeats],
                        help="what the routes do besides the models (the ship's step idle)")
    mem = commands.add_parser("memory", help="peak memory of a long run streamed to disk, "
                                             "both backends")
    mem.add_argument("--hours", type=float, default=24.0, help="simulated hours (default 24)")
    sweep = commands.add_parser("sweep", help="sweeps on every backend with 1 and 2 workers, "
                                             "the batch route's campaign and memory")
    sweep.add_argument("--parts", nargs="+", choices=SWEEP_PARTS, default=list(SWEEP_PARTS),
                       help="what to measure (default: all, in this order)")
    sweep.add_argument("--runs", type=int, default=32,
                       help="runs per FMI or in-process sweep (even; default 32)")
    sweep.add_argument("--batch-runs", type=int, default=1024,
                       help="runs per batch sweep (even; default 1024)")
    sweep.add_argument("--sea", choices=("waves", "calm", "both"), default="both",
                       help="the throughput's sweeps: waves_pd and waves_smc, calm_pd and "
                            "calm_smc, or both (default)")
    sweep.add_argument("--rounds", type=int, default=1,
                       help="throughput sweeps of each backend, in turn (default 1); medians")
    sweep.add_argument("--campaign-runs", type=int, default=sweep_timing.CAMPAIGN_RUNS,
                       help=f"waves_pd runs of the campaign (default "
                            f"{sweep_timing.CAMPAIGN_RUNS})")
    sweep.add_argument("--memory-members", type=_counts, default=sweep_timing.MEMORY_MEMBERS,
                       help="members of the memory measurement, comma-separated (default "
                            + ",".join(map(str, sweep_timing.MEMORY_MEMBERS)) + ")")
    rl = commands.add_parser("rl", parents=[repeats],
                             help="ShipVectorEnv against a SyncVectorEnv of ShipEnv")
    rl.add_argument("--ships", type=_counts, default=(256, 1000),
                    help="ships per env, comma-separated (default 256,1000)")
    commands.add_parser("all", parents=[repeats], help="engines, overhead, memory, sweep and "
                                                      "rl in turn, each with its defaults")
    args = parser.parse_args(argv)
    own = {"memory": mem, "sweep": sweep, "rl": rl}
    try:
        for name in BENCHMARKS if args.command == "all" else (args.command or "engines",):
            _benchmark(name, args if name == args.command or name not in own
                       else own[name].parse_args([]), getattr(args, "repeats", 5))
    except (RuntimeError, ValueError, FileNotFoundError) as error:   # e.g. stale FMUs
        say_error(error)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
