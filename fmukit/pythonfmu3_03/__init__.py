"""FMI 3.0 through pythonfmu3 0.3.4, and what fmukit owes to its defects (under ``ACTIVE``):
references released once per exception (``fmukit.entry``), every exception fmi3Fatal
(``Fmi3Entry.do_step`` returns fmi3Error), log messages forwarded whatever ``loggingOn``
(``Fmi3Entry.log``), a double free at exit (``binary``), units, ranges, exact starts,
dependencies and the instance-only description, author, default experiment (``slave``).
"""
from pythonfmu3 import __version__ as PYTHONFMU_VERSION

ACTIVE = PYTHONFMU_VERSION == "0.3.4"         # the version whose defects these are
