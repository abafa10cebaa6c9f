"""Every FMI entry point of a slave passes through ``fmi_entry``: pythonfmu 0.7's error path, made safe.

pythonfmu 0.7 turns every Python exception into fmi2Fatal. Its C++ layer also
releases the instance, its class and its log queue once per exception and again
at fmi2FreeInstance, a use-after-free that crashes the host later. ``fmi_entry``
takes one extra reference on those three objects before an exception leaves
Python, so the host survives; and it echoes the error to standard error when
FMUKIT_LOG_STDERR is set, for hosts that drop FMU log messages (ecos 0.7
installs a no-op logger).
"""
from __future__ import annotations

import ctypes
import functools
import os
import sys
from typing import Any, Callable

from pythonfmu import __version__ as PYTHONFMU_VERSION

_RELEASES_ON_EXCEPTION = PYTHONFMU_VERSION == "0.7.0"


def echo(slave: Any, message: str) -> None:
    """Also write an error to standard error if FMUKIT_LOG_STDERR is set."""
    if os.environ.get("FMUKIT_LOG_STDERR"):
        print(f"[{slave.instance_name}] {message}", file=sys.stderr, flush=True)


def fmi_entry(method: Callable) -> Callable:
    """Let an exception reach pythonfmu's C++ layer without corrupting the host."""
    @functools.wraps(method)
    def entry(self, *args):
        try:
            return method(self, *args)
        except Exception as error:
            echo(self, f"{method.__name__}: {error!r}")
            if _RELEASES_ON_EXCEPTION:
                for obj in (self, type(self), self.log_queue):
                    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))
            raise
    return entry
