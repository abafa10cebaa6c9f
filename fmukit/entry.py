"""``fmi_entry``, through which every FMI entry point of a slave passes: pythonfmu's error path
made safe.

Both pythonfmus turn every exception into a fatal status, and their C++ layers release the
instance, its class and its log queue once per exception (a use-after-free that crashes the
host later): where the adapter says so (``RELEASES_ON_EXCEPTION``) one extra reference is
taken on each. The refusal is logged under its category (``fmukit.<cause>``), or written to
standard error when the host does not listen. With ``error_result`` (FMI 3.0's doStep) a
refusal returns that result, logged as an error, instead of raising.
"""
from __future__ import annotations

import ctypes
import functools
from typing import Any, Callable

from .refusals import Refused, explain, naming


def fmi_entry(method: Callable | None = None, *,
              error_result: Callable[[], Any] | None = None) -> Callable:
    """Let an exception reach pythonfmu's C++ layer without corrupting the host; with
    ``error_result``, a refusal returns ``error_result()`` instead (see the module
    docstring). Usable as ``@fmi_entry`` and ``@fmi_entry(error_result=...)``."""
    if method is None:
        return functools.partial(fmi_entry, error_result=error_result)

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
            status = self.STATUS_FATAL if error_result is None else self.STATUS_ERROR
            self.log(naming(self.instance_name, str(refused)), status, refused.category)
            self.host_log.tell(self.instance_name, str(refused))
            if error_result is not None:
                return error_result()
            if self.RELEASES_ON_EXCEPTION:     # the C++ layer releases them once per exception
                for obj in (self, type(self), self.log_queue):
                    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))
            raise refused from error
    return entry


def unguarded(entry_point: Callable) -> Callable:
    """The bound method behind an ``fmi_entry``: for a host in the same process, which
    handles exceptions itself (pythonfmu's C++ layer is not there)."""
    return entry_point.__func__.__wrapped__.__get__(entry_point.__self__)
