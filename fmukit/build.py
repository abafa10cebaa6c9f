"""``python -m fmukit.build``: the build command's published name (``fmubuild.cli``).

Host-only, like all of ``fmubuild``: no FMU carries this module.
"""
import sys

from fmubuild.cli import main

if __name__ == "__main__":
    sys.exit(main())
