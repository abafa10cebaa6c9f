"""Interop with other FMI co-simulation tools: SSP packages, and runs in other engines.

- ``ssp``: a scenario exported as a self-contained SSP package (the route as numbers,
  the step for OSP and OMSimulator; this project's FMI 2.0 FMUs or their FMI 3.0 twins),
  and read back;
- ``osp``: the same system as OSP's OspSystemStructure.xml, beside the package;
- ``engines``: a package (or, for libcosim, the OSP file) run in OSP libcosim, ecos or
  fmpy's SSP runner, in a child process, with failures those engines hide turned into
  ``EngineError`` (and FMI 3.0 FMUs refused by the two that take FMI 2.0 only);
- ``omsimulator``: a package run in OMSimulator's command line or Python API.
"""
