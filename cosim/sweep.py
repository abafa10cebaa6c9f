"""python -m cosim.sweep SPEC [options]: a Monte Carlo sweep on Dask (docs/sweeps.md)."""
from __future__ import annotations

import argparse
import os
import shlex
import signal
import sys
from pathlib import Path

from ._cli import (add_isolation_options, count, entry, isolation, positive_seconds, say_error,
                   say_note, writable_folder)
from .core.interrupt import Interrupted
from .core.watchdog import STEP_LIMIT_S, Limits
from .studies import campaign
from .studies.cluster import CONNECT_TIMEOUT, NoWorkers, SweepError
from .studies.sweep_spec import MAX_RUNS, Spec
from .studies.sweep_task import BATCH, SWEEP_BACKENDS
from .studies.sweep_tables import distinct, summary, write_comparison, write_tables

EXAMPLES = """\
  python -m cosim.sweep docs/sweeps/smc_vs_pd.toml             # local cluster, 1 worker/core
  python -m cosim.sweep SPEC --scheduler tcp://host:8786       # an existing Dask cluster
  python -m cosim.sweep SPEC --workers 2 --csv --out results/sweeps
  python -m cosim.sweep SPEC --backend batch                   # many runs per task

SPEC: a TOML file of controllers, axes and plots (docs/sweeps.md, docs/sweeps/example.toml)."""

OUTPUTS = ("results.parquet", "results.json", "results.csv", "summary.csv", "J_distribution.png",
           "tracks.png", "J_*_over_pd.png", "comparison.md")    # written beside the journal


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.sweep", epilog=EXAMPLES,
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     description="Ensembles of co-simulations on Dask: Monte "
                                                 "Carlo over seeds, sea states and settings.")
    parser.add_argument("spec", type=Path, help="sweep file (TOML)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler "
                        "(default: DASK_SCHEDULER_ADDRESS, else a local cluster)")
    parser.add_argument("--scheduler-file", metavar="FILE", help="the same, from its file")
    parser.add_argument("--workers", type=count, help="a local cluster's worker processes "
                        "(default and most: this process's cores)")
    parser.add_argument("--connect-timeout", type=positive_seconds, metavar="SECONDS",
                        default=CONNECT_TIMEOUT, help="to reach a scheduler (%(default)g s)")
    parser.add_argument("--max-runs", type=count, metavar="N", default=MAX_RUNS,
                        help="refuse a spec of more runs (default: %(default)d)")
    parser.add_argument("--out", type=Path, default=Path("results/sweeps"),
                        help="parent folder of the results")
    parser.add_argument("--backend", choices=SWEEP_BACKENDS, default="fmi", help="fmi "
                        "(default); inprocess: our FMUs without FMI; batch: a system's runs "
                        "stepped together as arrays; the same rows, bit for bit")
    parser.add_argument("--batch-size", type=count, metavar="N", help="with --backend batch: at "
                        f"most N runs a batch (default: as few as keep every worker busy, of at "
                        f"most {campaign.MAX_BATCH} runs and, where there are as many, at least "
                        f"{campaign.MIN_BATCH})")
    parser.add_argument("--no-worker-timeout", type=positive_seconds, metavar="SECONDS",
                        default=campaign.NO_WORKER_TIMEOUT, help="stop, every row kept, when the "
                        f"cluster has had no worker this long (exit {NoWorkers.exit_status}; "
                        "default: %(default)g s)")
    parser.add_argument("--step-timeout", type=positive_seconds, default=STEP_LIMIT_S,
                        metavar="S", help="fail a run with a step (or instantiation) over S s; a "
                        "batch of N runs gets N times S (default %(default)g)")
    parser.add_argument("--run-timeout", type=positive_seconds, metavar="S", help="fail a run "
                        "over S s; a batch of N runs gets N times S (default: no limit)")
    parser.add_argument("--csv", action="store_true", help="also write results.csv")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar (for logs)")
    add_isolation_options(parser, "foreign")
    args = parser.parse_args(argv)
    isolated = isolation(parser, args)
    if args.batch_size is not None and args.backend != BATCH:
        parser.error(f"--batch-size sizes the batches of --backend batch, not of "
                     f"--backend {args.backend}")
    try:
        spec = Spec.read(args.spec, max_runs=args.max_runs)
    except (ValueError, FileNotFoundError) as error:     # FileNotFoundError: an FMU
        say_error(error)
        return 2
    except Interrupted as stopped:
        print(f"{stopped} while reading {args.spec}: no run was started", file=sys.stderr)
        return stopped.exit_status
    for controller, shipped in spec.bundles().items():     # what to isolate, before any run
        try:
            isolated.check(shipped.system.components)
        except ValueError as error:
            parser.error(f"controller {controller!r}: --{error}")
    out = writable_folder(args.out / spec.name)
    stage = "running the sweep"
    try:
        for note in [*spec.backend_notes(args.backend), *spec.sharing_notes()]:
            say_note(note)
        rows = campaign.execute(spec, out, args.scheduler, args.workers, not args.no_progress,
                                scheduler_file=args.scheduler_file, backend=args.backend,
                                limits=Limits(args.step_timeout, args.run_timeout),
                                no_worker_timeout=args.no_worker_timeout,
                                connect_timeout=args.connect_timeout, batch_size=args.batch_size,
                                isolation=isolated)
        stage = "writing the tables"
        written = write_tables(rows, out, args.csv, spec)
        stage = "drawing the figures"
        if any(r["status"] == "ok" for r in rows):
            from .studies.sweep_figures import save_figures      # matplotlib: only to draw
            written += save_figures(spec, rows, out)
        else:
            print("no run succeeded: no figures drawn", file=sys.stderr)
        stage = "writing comparison.md"
        written += write_comparison(spec, rows, out)
    except (SweepError, ValueError, OSError) as error:  # OSError: the journal's folder, or
        say_error(error)                                # OutputError, which names its file
        if isinstance(error, OSError) and stage != "running the sweep":
            print(f"  every row is kept in {out / 'runs.jsonl'}; the same command writes the "
                  "tables and figures again", file=sys.stderr)
        return 2
    except (Interrupted, NoWorkers) as stopped:     # what is kept, and how to resume
        rows = campaign.completed(spec, out)
        running = stage == "running the sweep"
        written = write_tables(rows, out, args.csv, spec) if running and rows else []
        done, runs = distinct(rows), len(spec.shared_runs())
        then = ("resumes the sweep" if sum(r["status"] == "ok" for r in done) < runs else
                "runs nothing again, and writes the tables and figures")
        resume = shlex.join([sys.executable, "-m", "cosim.sweep",
                             *(sys.argv[1:] if argv is None else argv)])
        print(f"{stopped}{'' if running else f' while {stage}'}: {len(done)} of {runs} runs "
              f"done, kept in {out / 'runs.jsonl'}{''.join(f', {p}' for p in written)}; this "
              f"command {then}: {resume}", file=sys.stderr)
        return stopped.exit_status
    for pattern in OUTPUTS:                 # a previous spec's, not rewritten: misleading
        for stale in out.glob(pattern):
            if stale not in written:
                stale.unlink()
    print(summary(spec, rows))
    print(f"wrote {', '.join(str(p) for p in written)}")
    return 0 if all(r["status"] == "ok" for r in rows) else 1


if __name__ == "__main__":
    status = entry(main)
    for number in (signal.SIGINT, signal.SIGTERM):      # as Python shuts down: no traceback
        signal.signal(number, lambda number, frame: os._exit(128 + number))
    sys.exit(status)
