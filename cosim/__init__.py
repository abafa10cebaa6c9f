"""Ship-autopilot co-simulation (Tomera 2010): the master, the paper's scenarios, and what is
built on them. Sub-packages, each importing only those before it: ``core`` (the master and
its backends), ``ensemble`` (the batch kernel), ``scenarios``, ``analysis``, ``interop``,
``studies``. Here: ``simulate`` and ``simulate_many`` (``api``), ``run_and_write``
(``outputs``), the pytest plugin (``testing``) and the commands, which nothing imports.
"""
from .api import SimulationError, simulate, simulate_many
from .outputs import run_and_write

__all__ = ["simulate", "simulate_many", "SimulationError", "run_and_write"]
