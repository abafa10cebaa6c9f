"""FMI 3.0 through pythonfmu3 0.3.4: the only package that imports pythonfmu3, and what fmukit
owes to that version's defects, each active only under ``ACTIVE``:

- its C++ ``handle_py_exception`` releases the instance, its class and its log queue once
  per exception (``fmukit.entry`` takes extra references);
- every exception is fmi3Fatal (``slave.Fmi3Entry.do_step`` returns fmi3Error for a refused
  step instead, after which fmi3Reset works);
- it forwards log messages whatever the host's ``loggingOn`` (``fmukit.entry.HostLog``
  reads the flag; ``Fmi3Entry.log`` holds messages back while it is off);
- its x86_64-linux binary frees its ``shared_ptr<PyState>`` twice at exit (``binary``,
  patched by ``fmubuild.exit_fix``);
- its modelDescription.xml lacks units, ranges, exact starts, dependencies, and the
  description, author and default experiment, which it reads from the instance only.
"""
from pythonfmu3 import __version__ as PYTHONFMU_VERSION

ACTIVE = PYTHONFMU_VERSION == "0.3.4"
"""Whether the compensations apply: to pythonfmu3 0.3.4, whose defects they are for."""
