"""FMI 3.0 through pythonfmu3 0.3.4: the only package that imports pythonfmu3, and what fmukit
owes to that version's defects, each active only under ``ACTIVE``: its C++ layer releases an
instance's references once per exception (``fmukit.entry``) and makes every exception
fmi3Fatal (``slave.Fmi3Entry.do_step`` returns fmi3Error for a refused step, after which
fmi3Reset works); it forwards log messages whatever the host's ``loggingOn``
(``fmukit.entry.HostLog``, ``Fmi3Entry.log``); its x86_64-linux binary frees its
``shared_ptr<PyState>`` twice at exit (``binary``); its modelDescription.xml lacks units,
ranges, exact starts, dependencies, and the description, author and default experiment,
which it reads from the instance only (``slave``).
"""
from pythonfmu3 import __version__ as PYTHONFMU_VERSION

ACTIVE = PYTHONFMU_VERSION == "0.3.4"
"""Whether the compensations apply: to pythonfmu3 0.3.4, whose defects they are for."""
