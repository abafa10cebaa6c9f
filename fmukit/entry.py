"""Every FMI entry point's error path made safe (``fmi_entry``: both pythonfmus' C++ layers
release the instance, its class and its log queue once per exception), and the error told to
the user where the host does not hear it (``HostLog``, reading the host's flag in the binary)."""
from __future__ import annotations

import ctypes
import functools
import hashlib
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from .refusals import Refused, explain, naming


def fmi_entry(method: Callable | None = None, *,
              error_result: Callable[[], Any] | None = None) -> Callable:
    """``method`` made safe, a refusal logged as ``fmukit.<cause>``; with ``error_result``
    (FMI 3.0's doStep) it returns ``error_result()`` instead of raising."""
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
    """The bound method behind an ``fmi_entry``, for a host in this process."""
    return entry_point.__func__.__wrapped__.__get__(entry_point.__self__)


@dataclass(frozen=True)
class Binary:
    """A pythonfmu binary fmukit knows inside out."""
    offset: int                 # file offset of onLibraryUnload
    code: bytes                 # its first instructions
    patched: bytes              # what they become (fmubuild.packaging.fix_exit)
    fixed_sha256: str           # the binary once patched
    logger_offset: int          # where the host's logging flag is, from the logger
    through_pointer: bool = False   # there is a pointer to the flag instead


class HostLog:
    """Where an FMU's errors reach its user: the host's logger (by its flag in a known
    binary, else if ``unknown``; always in this process), else standard error, never both."""

    def __init__(self, kwargs: dict[str, Any], known_binaries: dict[str, Binary],
                 unknown: bool):
        logger, resources = kwargs.get("logger"), kwargs.get("resources")
        fixed = {b.fixed_sha256: b for b in known_binaries.values()}
        binaries = (Path(resources).parent / "binaries").glob("*/*") if logger and resources else ()
        digests = (hashlib.sha256(p.read_bytes()).hexdigest() for p in binaries if p.is_file())
        known = next((fixed[d] for d in digests if d in fixed), None)
        address = None if known is None else logger + known.logger_offset
        if known is not None and known.through_pointer:
            address = ctypes.c_void_p.from_address(address).value
        self._flag = ctypes.c_bool.from_address(address) if address else None
        self._in_process, self._unknown = "logger" not in kwargs, unknown
        self._told = ""

    def hears(self) -> bool:
        """Whether the host receives this FMU's log messages now."""
        return self._in_process or (bool(self._flag.value) if self._flag is not None
                                    else self._unknown)

    def tell(self, instance_name: str, message: str) -> None:
        """Write an error to standard error if the host will not hear it, once per reason."""
        if not self.hears() and message != self._told:
            sys.stderr.write(naming(instance_name, message) + "\n")   # one write: hosts
            sys.stderr.flush()                              # step FMUs in parallel threads
            self._told = message
