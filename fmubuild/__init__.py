"""Building FMUs, on the host; ``cli`` is ``python -m fmukit.build``."""
