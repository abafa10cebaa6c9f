"""FMI 2.0 through pythonfmu 0.7.0: the adapter, and what fmukit owes to that version's defects.

This folder is the only place that imports pythonfmu. The compensations for
pythonfmu 0.7.0's defects are active only under ``ACTIVE``:

- ``slave``: ``Fmi2Entry``, the FMI 2.0 half of an FMU's class (``on_fmi2``); its
  binary releases an instance's references once per Python exception, a
  use-after-free that crashes the host (``fmukit.entry`` takes extra references);
- ``hostlog``: pythonfmu forwards log messages only while the host has debug
  logging on; the host's flag is read, and errors go to standard error when it is off;
- ``binary``: pythonfmu 0.7.0's linux64 binary as fmukit knows it (its exit-time heap
  corruption is patched when an FMU is built: ``fmubuild.exit_fix``);
- ``model_description``: what pythonfmu 0.7 leaves out of modelDescription.xml.

The host's Ctrl-C is ``fmukit.hostsignals``', the same for both pythonfmu versions.
Replacing pythonfmu is adding a folder like this one beside it (as
``fmukit.pythonfmu3_03`` is for FMI 3.0) and naming it in ``fmukit.compose``;
retiring it, deleting this one.
"""
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave
from pythonfmu import Fmi2Variability, Integer, Real, String
from pythonfmu import __version__ as PYTHONFMU_VERSION
from pythonfmu.enums import Fmi2Status

ACTIVE = PYTHONFMU_VERSION == "0.7.0"
"""Whether the compensations apply: to pythonfmu 0.7.0, whose defects they are for."""

__all__ = ["ACTIVE", "PYTHONFMU_VERSION", "Fmi2Causality", "Fmi2Initial", "Fmi2Slave",
           "Fmi2Status", "Fmi2Variability", "Integer", "Real", "String"]
