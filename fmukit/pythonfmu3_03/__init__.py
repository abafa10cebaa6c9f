"""FMI 3.0 through pythonfmu3 0.3.4: the adapter, and what fmukit owes to that version's defects.

This folder is the only place that imports pythonfmu3, the FMI 3.0 twin of
``fmukit.pythonfmu07``. pythonfmu3 0.3.4's defects, and what fmukit does about them,
each active only under ``ACTIVE``:

- two Python exceptions in one instance crash the host (its C++
  ``handle_py_exception`` releases the instance, its class and its log queue):
  ``fmukit.entry`` takes the extra references, as for pythonfmu 0.7.0;
- every exception is fmi3Fatal: ``slave.Fmi3Entry.do_step`` returns
  ``Fmi3StepResult(status=error)`` for a refused step instead (fmi3Error, after which
  fmi3Reset works), the one non-fatal status pythonfmu3 passes on; and it always returns
  a result, whose ``terminateSimulation`` pythonfmu3 writes only from one;
- log messages reach the host whether or not it asked for them (``loggingOn``):
  ``hostlog`` reads the host's flag, and ``Fmi3Entry.log`` keeps messages off the
  host's callback while it is off (errors go to standard error then);
- the host's Ctrl-C: ``fmukit.hostsignals``, as for pythonfmu 0.7.0 (the same embedding);
- the exit-time use-after-free of its ``shared_ptr<PyState>`` (``onLibraryUnload``):
  ``binary``, patched by ``fmubuild.exit_fix``;
- the model description: ``model_description`` completes it; the description, author
  and default experiment it reads from the instance only, where its ``__init__`` sets
  them to None: ``Fmi3Entry`` sets them from the class.
"""
from pythonfmu3 import Fmi3Causality, Fmi3Initial, Fmi3Slave, Fmi3Status, Fmi3StepResult
from pythonfmu3 import Fmi3Variability, Float64, Int32, String
from pythonfmu3 import __version__ as PYTHONFMU_VERSION

ACTIVE = PYTHONFMU_VERSION == "0.3.4"
"""Whether the compensations apply: to pythonfmu3 0.3.4, whose defects they are for."""

__all__ = ["ACTIVE", "PYTHONFMU_VERSION", "Fmi3Causality", "Fmi3Initial", "Fmi3Slave",
           "Fmi3Status", "Fmi3StepResult", "Fmi3Variability", "Float64", "Int32", "String"]
