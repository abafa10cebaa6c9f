"""Build every FMU of the project into fmus/ and validate it.

    python -m fmukit.build            # all FMUs
    python -m fmukit.build ship       # only some

What each FMU carries and how it is checked: ``fmukit.packaging``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .packaging import FMU_DIR, FMUS, build


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", choices=[[], *FMUS], metavar="NAME",
                        help=f"FMUs to build (default: all of {', '.join(FMUS)})")
    parser.add_argument("--dest", type=Path, default=FMU_DIR, help="output folder")
    args = parser.parse_args(argv)
    for name in args.names or FMUS:
        print(f"built and validated {build(name, args.dest)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
