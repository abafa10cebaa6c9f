"""Every FMI entry point of a slave passes through ``fmi_entry``: pythonfmu 0.7's error path, made safe.

pythonfmu 0.7 turns every Python exception into fmi2Fatal. Its C++ layer also
releases the instance, its class and its log queue once per exception and again
at fmi2FreeInstance, a use-after-free that crashes the host later. ``fmi_entry``
takes one extra reference on those three objects before any exception leaves
Python, so the host survives; and it tells the user why, through the host's
logger (a message whose category, ``fmukit.<cause>``, says what was refused) or on
standard error (``hostlog``). A KeyboardInterrupt (or any
other BaseException) raised in FMU code fails the FMU like a refusal does
(``ModelSlave.interrupted``).
"""
from __future__ import annotations

import ctypes
import functools
from typing import Callable

from ..refusals import Refused, explain, naming
from . import ACTIVE, Fmi2Status


def fmi_entry(method: Callable) -> Callable:
    """Let an exception reach pythonfmu's C++ layer without corrupting the host."""
    @functools.wraps(method)
    def entry(self, *args):
        try:
            return method(self, *args)
        except BaseException as error:
            if not isinstance(error, Exception):  # Ctrl-C or the like: the FMU has failed
                error = self.interrupted(method.__name__, error)
            refused = (error if isinstance(error, Refused)
                       else Refused(f"{method.__name__}: {explain(error)}", "model"))
            # The cause as data: the category. pythonfmu logs the exception too, with none.
            self.log(naming(self.instance_name, str(refused)), Fmi2Status.fatal, refused.category)
            self.host_log.tell(self.instance_name, str(refused))
            if ACTIVE:             # pythonfmu 0.7.0 releases them once per exception
                for obj in (self, type(self), self.log_queue):
                    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))
            raise refused from error
    return entry


def unguarded(entry_point: Callable) -> Callable:
    """The bound method behind an ``fmi_entry``: for a host in the same process, which
    handles exceptions itself (pythonfmu's C++ layer is not there)."""
    return entry_point.__func__.__wrapped__.__get__(entry_point.__self__)
