"""The co-simulation core: components, systems, the master and its parts.

``instance`` (what the master needs of a component) with its backends ``fmi`` (FMI 2.0 and
3.0 through fmpy) and ``inprocess`` (the FMUs' Python classes);
``system`` and ``ssd`` (a system, read and written as SSP); ``values`` (a value checked
against its declaration); ``errors``; ``wiring`` and ``coupling``; ``recording``;
``interrupt`` and ``watchdog`` (signals and time limits); ``files`` (outputs written whole);
``master``. It imports nothing of the project: where FMUs are built, the caller says
(``system.FmuFolders``).
"""
