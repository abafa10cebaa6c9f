"""FMI 2.0 through pythonfmu 0.7.0, and what fmukit owes to its defects (under ``ACTIVE``):
references released once per exception (``fmukit.entry``) and the entry module's namespace
once per instantiation (``slave.hold_namespace``), log messages forwarded only under debug
logging (``fmukit.entry.HostLog``), a heap corrupted at exit (``binary``), units, ranges and
dependencies left out of modelDescription.xml (``slave``).
"""
from pythonfmu import __version__ as PYTHONFMU_VERSION

ACTIVE = PYTHONFMU_VERSION == "0.7.0"         # the version whose defects these are
