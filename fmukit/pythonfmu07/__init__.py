"""Everything fmukit owes to pythonfmu 0.7.0, behind one version gate.

The runtime is written against pythonfmu's ``Fmi2Slave`` (FMI 2.0 co-simulation);
this folder is the only place that imports pythonfmu, and it holds the compensations
for pythonfmu 0.7.0's defects, each active only under ``ACTIVE``:

- ``entry``: every FMI entry point; pythonfmu releases an instance's references once
  per Python exception, a use-after-free that crashes the host (extra references);
- ``hostlog``: pythonfmu forwards log messages only while the host has debug
  logging on; the host's flag is read, and errors go to standard error when it is off;
- ``signals``: the host's Ctrl-C is handled in the host's own code, not in FMU code
  that pythonfmu runs inside the host's interpreter;
- ``binary``: pythonfmu 0.7.0's linux64 binary as fmukit knows it (its exit-time heap
  corruption is patched when an FMU is built: ``fmubuild.exit_fix``).

Replacing pythonfmu is adding a folder like this one beside it and importing it in
``fmukit.slave`` and ``fmukit.registry``; retiring it, deleting this one.
"""
from pythonfmu import DefaultExperiment, Fmi2Causality, Fmi2Initial, Fmi2Slave
from pythonfmu import Fmi2Variability, Integer, Real, String
from pythonfmu import __version__ as PYTHONFMU_VERSION
from pythonfmu.enums import Fmi2Status

ACTIVE = PYTHONFMU_VERSION == "0.7.0"
"""Whether the compensations apply: to pythonfmu 0.7.0, whose defects they are for."""

__all__ = ["ACTIVE", "PYTHONFMU_VERSION", "DefaultExperiment", "Fmi2Causality", "Fmi2Initial",
           "Fmi2Slave", "Fmi2Status", "Fmi2Variability", "Integer", "Real", "String"]
