"""Run an SSP package in another engine (``cosim.interop.hosts``) and save the signals; a
failure is status 1 with the engine's messages."""
import argparse
import sys
from pathlib import Path

from ._cli import entry
from .core.files import OutputError
from .interop.hosts import ENGINES, TRACED, EngineError, run, save_trace


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.engines",
                                     description="Run an SSP package in another engine "
                                                 "and save the recorded signals.")
    parser.add_argument("engine", choices=ENGINES)
    parser.add_argument("ssp", type=Path)
    parser.add_argument("--out", type=Path, required=True, help=".npz file to write")
    parser.add_argument("--signals", nargs="+", default=list(TRACED),
                        help="component.variable names to record (Real)")
    parser.add_argument("--events", type=Path, metavar="FILE",
                        help="timed events, OSP's scenario file (libcosim only)")
    args = parser.parse_args(argv)
    try:
        result = run(args.engine, args.ssp, tuple(args.signals), args.events)
        save_trace(args.out, result)
    except ValueError as error:                     # events for an engine without them
        parser.error(str(error))
    except (EngineError, OutputError) as error:     # EngineError: with the FMU's message
        print(f"error: {error}", file=sys.stderr)
        return 1
    print(f"wrote {args.out}: {', '.join(args.signals)} at {len(result['time'])} times")
    return 0


if __name__ == "__main__":
    sys.exit(entry(main))
