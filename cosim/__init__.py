"""Ship-autopilot co-simulation: the master, the paper's scenarios, and what is built on them.

Layers, each a sub-package whose docstring says more:

- ``cosim.core``: the co-simulation core. Component backends (FMUs through fmpy, their
  Python classes in-process, a null backend), SSP system descriptions, wiring and
  ordering, the Gauss-Seidel and Jacobi couplings, recording, and the ``Master``.
- ``cosim.ensemble``: the batch kernel: many runs of one course-keeping system stepped
  together as numpy arrays, bit for bit the in-process route's.
- ``cosim.scenarios``: the scenarios as .ssd files, and their registry.
- ``cosim.analysis``: what is computed from a recorded run: metrics, eq (19), reports,
  figures, sea states.
- ``cosim.interop``: other FMI tools: SSP packages, libcosim, ecos, fmpy's SSP runner.
- ``cosim.studies``: studies built on the above: ensembles on Dask, benchmarks, the
  in-process reference.

On top of them, directly in ``cosim/``: the Python entry points ``cosim.simulate`` and,
for many runs of one scenario, ``cosim.simulate_many`` (``api.py``), a run with what it
writes (``outputs.py``: ``cosim.run_and_write``, the one lifecycle of a run and its files),
the pytest plugin (``testing.py``), and the commands (``python -m cosim.run``,
``cosim.sweep``, ``cosim.export``, ``cosim.bench``, ``cosim.engines``, ``cosim.score``,
``cosim.accuracy``), which parse options and print; ``_cli.py`` is what they share. A
module imports only from the sub-packages listed before its own (the core from none);
nothing imports a command.
"""
from .api import SimulationError, simulate, simulate_many
from .outputs import run_and_write

__all__ = ["simulate", "simulate_many", "SimulationError", "run_and_write"]
