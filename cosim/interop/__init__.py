"""Interop with other FMI co-simulation tools: SSP packages, and runs in other engines.

- ``ssp``: a scenario exported as a self-contained SSP package, and read back;
- ``engines``: a package run in OSP libcosim, ecos or fmpy's SSP runner, in a child
  process, with failures those engines hide turned into ``EngineError``.
"""
