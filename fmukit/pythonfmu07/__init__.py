"""FMI 2.0 through pythonfmu 0.7.0: the only package that imports pythonfmu, and what fmukit
owes to that version's defects, each active only under ``ACTIVE``: its C++ layer releases an
instance's references once per exception (``fmukit.entry``) and the entry module's namespace
once per instantiation (``slave.hold_namespace``); it forwards log messages only while the
host has debug logging on (``fmukit.entry.HostLog``); its linux64 binary corrupts the heap
at exit (``binary``); it leaves units, ranges and dependencies out of modelDescription.xml
(``slave``). Retiring it is deleting this folder and its entry in ``fmukit.compose``.
"""
from pythonfmu import __version__ as PYTHONFMU_VERSION

ACTIVE = PYTHONFMU_VERSION == "0.7.0"
"""Whether the compensations apply: to pythonfmu 0.7.0, whose defects they are for."""
