"""The co-simulation core: components, system descriptions, the master and its parts.

- ``instance``: what the master needs of a component (``Instance``, ``FmuCallError``),
  with three backends: ``fmi`` (FMUs through fmpy), ``inprocess`` (the FMUs' Python
  classes without FMI) and ``null`` (interfaces only, to measure the master);
- ``ssd``: SSP system structure descriptions, read and written;
- ``values``: a parameter value checked against its FMU's declaration (type, range)
  before any FMU call, the same on every backend;
- ``errors``: an FMU file missing or unreadable, and whether it is one this project builds;
- ``wiring``: connection checks, the Gauss-Seidel order, the column layout;
- ``coupling``: the Gauss-Seidel and Jacobi steps;
- ``recording``: the rows of a run, in memory or streamed to CSV;
- ``interrupt``: Ctrl-C and SIGTERM taken between two steps (``StopSignals``);
- ``watchdog``: step and run time limits, and signals, that hold while an FMU hangs;
- ``files``: output files written whole or not at all, output folders locked;
- ``provenance``: what it takes to reproduce a run, written as JSON beside its CSV;
- ``master``: ``Master``, which wires, orders and delegates to the above.

No code here depends on the ship, the paper or the command line (the docstrings use
the paper's diagram as their example); studies, reports and interop with other
engines are built on top (``cosim.analysis``, ``cosim.studies``,
``cosim.interop``).
"""
