"""Building FMUs, on the host (no FMU carries this package); ``cli`` is ``python -m fmukit.build``.
"""
