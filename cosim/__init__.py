"""Ship-autopilot co-simulation (Tomera 2010): ``simulate``, ``simulate_many`` and
``run_and_write``; its layers and commands are in docs/architecture.md."""
from .api import SimulationError, simulate, simulate_many
from .outputs import run_and_write

__all__ = ["simulate", "simulate_many", "SimulationError", "run_and_write"]
