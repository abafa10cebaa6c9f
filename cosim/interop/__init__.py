"""Interop with other FMI co-simulation tools: SSP packages, and runs in other engines.

- ``ssp``: a scenario exported as a self-contained SSP package (the route as numbers,
  the step for OSP and OMSimulator), and read back;
- ``osp``: the same system as OSP's OspSystemStructure.xml, beside the package;
- ``engines``: a package (or, for libcosim, the OSP file) run in OSP libcosim, ecos or
  fmpy's SSP runner, in a child process, with failures those engines hide turned into
  ``EngineError``;
- ``omsimulator``: a package run in OMSimulator's command line or Python API.
"""
