"""How large are the set-up's own numerical errors? RK4 against DOP853, co-simulation
against a monolithic model with the controller inside the solver.

    python -m cosim.accuracy            # the full study (docs/reproduction.md)
    python -m cosim.accuracy --quick    # shorter runs in calm water, fewer steps (CI)
    python -m cosim.accuracy --cpus     # every scenario as other CPUs would run it, bit for bit

Prints its tables and writes them to accuracy.md with convergence.png (with --cpus: cpus.md).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ._cli import entry, writable_folder
from .core.files import write_atomically
from .scenarios import names
from .studies import cpu_variants, numerical_error


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.accuracy",
                                     description=__doc__.split("\n\n")[0],
                                     epilog=__doc__.split("\n\n", 1)[1],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="60 s open loop, 120 s closed loop, steps 0.1-0.025 s, calm runs")
    parser.add_argument("--out", type=Path, default=Path("results/accuracy"),
                        help="folder for accuracy.md and convergence.png "
                             "(default: results/accuracy)")
    parser.add_argument("--cpus", action="store_true",
                        help="instead: run every scenario under other CPUs' numpy dispatch, "
                             "OpenBLAS kernels and libm variants and compare bit for bit")
    args = parser.parse_args(argv)
    out = writable_folder(args.out)
    started = time.perf_counter()
    if args.cpus:
        table = cpu_variants.audit_table(cpu_variants.audit(names()))
        print(table)
        write_atomically(out / "cpus.md", lambda path: path.write_text(table + "\n"))
        print(f"wrote {out / 'cpus.md'} ({time.perf_counter() - started:.0f} s)")
        return 0
    open_end, closed_end = (60.0, 120.0) if args.quick else (400.0, None)
    runs = numerical_error.PAPER_RUNS[:2] if args.quick else numerical_error.PAPER_RUNS
    steps = (0.1, 0.05, 0.025) if args.quick else numerical_error.STEPS

    tables: list[str] = []

    def section(title: str, text: str) -> None:
        tables.extend([("\n" if tables else "") + f"## {title}\n", text])
        print("".join(tables[-2:]), flush=True)
    section("Integration error, open loop (calm water)", numerical_error.open_loop_table(
        [numerical_error.open_loop(p, open_end) for p in ("step", "sine", "zigzag")]))
    results = {name: numerical_error.study(name, steps, closed_end) for name in runs}
    section("Co-simulation at 0.1 s against the monolithic reference",
            numerical_error.closed_loop_table(results))
    section("J against the communication step", numerical_error.convergence_table(results))
    write_atomically(out / "accuracy.md", lambda path: path.write_text("\n".join(tables) + "\n"))
    figure = numerical_error.convergence_figure(results, out / "convergence.png")
    print(f"wrote {out / 'accuracy.md'}, {figure} ({time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
