"""The command line of ``cosim.interop.engines``: run an SSP package in another engine.

    python -m cosim.engines libcosim results/ssp/calm_pd.ssp --out trace.npz

Runs in this process and saves the recorded signals; ``cosim.interop.engines.run``
calls this command in a child process and checks what it recorded.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from ._cli import entry
from .interop.engines import ENGINES, RUNNERS, SIGNALS


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.engines",
                                     description="Run an SSP package in another engine "
                                                 "and save the recorded signals.")
    parser.add_argument("engine", choices=ENGINES)
    parser.add_argument("ssp", type=Path)
    parser.add_argument("--out", type=Path, required=True, help=".npz file to write")
    parser.add_argument("--signals", nargs="+", default=list(SIGNALS),
                        help="component.variable names to record (Real)")
    args = parser.parse_args(argv)
    try:
        result = RUNNERS[args.engine](args.ssp.resolve(), tuple(args.signals))
    except Exception as error:          # the engine's own exceptions, with their message
        print(f"error: {type(error).__name__}: {error}", file=sys.stderr)
        return 1
    np.savez(args.out, **result)
    print(f"wrote {args.out}: {', '.join(args.signals)} at {len(result['time'])} times")
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
