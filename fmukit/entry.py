"""Every FMI entry point of a slave passes through ``fmi_entry``: pythonfmu 0.7's error path, made safe.

pythonfmu 0.7 turns every Python exception into fmi2Fatal. Its C++ layer also
releases the instance, its class and its log queue once per exception and again
at fmi2FreeInstance, a use-after-free that crashes the host later. ``fmi_entry``
takes one extra reference on those three objects before any exception leaves
Python, so the host survives; and it tells the user why, through the host's
logger or on standard error (``fmukit.hostlog``). A KeyboardInterrupt (or any
other BaseException) raised in FMU code fails the FMU like a refusal does
(``ModelSlave.interrupted``).
"""
from __future__ import annotations

import ctypes
import functools
from typing import Callable

from pythonfmu import __version__ as PYTHONFMU_VERSION

_RELEASES_ON_EXCEPTION = PYTHONFMU_VERSION == "0.7.0"


class Refused(ValueError):
    """A call the FMU refuses; pythonfmu reports it as fmi2Fatal, with this message."""


def explain(error: BaseException) -> str:
    """What went wrong, for the user: a refusal's own message, or the exception's type and
    message."""
    return str(error) if isinstance(error, Refused) else f"{type(error).__name__}: {error}"


def fmi_entry(method: Callable) -> Callable:
    """Let an exception reach pythonfmu's C++ layer without corrupting the host."""
    @functools.wraps(method)
    def entry(self, *args):
        try:
            return method(self, *args)
        except BaseException as error:
            if not isinstance(error, Exception):  # Ctrl-C or the like: the FMU has failed
                error = self.interrupted(method.__name__, error)
            text = (explain(error) if isinstance(error, Refused)
                    else f"{method.__name__}: {explain(error)}")
            self.host_log.tell(self.instance_name, text)
            if _RELEASES_ON_EXCEPTION:
                for obj in (self, type(self), self.log_queue):
                    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))
            raise Refused(naming(self.instance_name, text)) from error
    return entry


def unguarded(entry_point: Callable) -> Callable:
    """The bound method behind an ``fmi_entry``: for a host in the same process, which
    handles exceptions itself (pythonfmu's C++ layer is not there)."""
    return entry_point.__func__.__wrapped__.__get__(entry_point.__self__)


def naming(instance_name: str, text: str) -> str:
    """A message as it leaves the FMU: naming the FMU, for hosts whose logs do not
    (libcosim's log shows neither the instance nor the call)."""
    return f"{instance_name}: {text}"


def unnamed(instance_name: str, message: str) -> str:
    """A message without the FMU's name in front, for a host that shows the name itself."""
    prefix = f"{instance_name}: "
    return message[len(prefix):] if message.startswith(prefix) else message

