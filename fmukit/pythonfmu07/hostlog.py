"""Whether the host hears an FMU's log messages, and standard error when it does not.

pythonfmu 0.7 forwards an FMU's log messages, errors included, only while the
host has debug logging on (``loggingOn`` of fmi2Instantiate, or
fmi2SetDebugLogging): fmpy's command line, for one, leaves it off, and its user
would never learn why a call failed. The FMU's Python side is handed the address
of pythonfmu's C++ logger (keyword ``logger``), which holds that flag. In the
binary fmukit builds (``binary.FIXED``: known layout, by SHA-256) the
flag is read there; an error goes to the host's logger when it listens, and to
standard error when it does not, never to both. With any other binary the flag
cannot be trusted, and every error also goes to standard error.
"""
from __future__ import annotations

import ctypes
import hashlib
import sys
from pathlib import Path

from ..refusals import naming
from .binary import FIXED


def _debug_flag(logger: int | None, resources: str | None) -> ctypes.c_bool | None:
    """The host's debug-logging flag inside pythonfmu's logger, if its layout is known."""
    if not logger or not resources:
        return None
    binaries = Path(resources).parent / "binaries"
    for binary in binaries.glob("*/*"):
        try:
            known = FIXED.get(hashlib.sha256(binary.read_bytes()).hexdigest())
        except OSError:
            continue
        if known is not None:
            return ctypes.c_bool.from_address(logger + known.debug_flag_offset)
    return None


class HostLog:
    """Where an FMU's errors reach its user: the host's logger, or standard error."""

    def __init__(self, logger: int | None, resources: str | None, in_process: bool):
        self._flag = _debug_flag(logger, resources)
        self._in_process = in_process        # a Python host that drains the log queue
        self._told = ""

    def hears(self) -> bool:
        """Whether the host receives this FMU's log messages now."""
        if self._in_process:
            return True
        return bool(self._flag.value) if self._flag is not None else False

    def tell(self, instance_name: str, message: str) -> None:
        """Write an error to standard error if the host will not hear it; once, not again
        for each following call that fails for the same reason."""
        if not self.hears() and message != self._told:
            sys.stderr.write(naming(instance_name, message) + "\n")   # one write: hosts
            sys.stderr.flush()                              # step FMUs in parallel threads
            self._told = message
