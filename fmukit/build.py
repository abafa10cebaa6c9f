"""``python -m fmukit.build``: the build command's published name (``fmubuild.cli``); host-only."""
from fmubuild.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
