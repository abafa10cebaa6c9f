"""The host's debug-logging flag in pythonfmu 0.7's logger, which alone decides what it hears.

pythonfmu 0.7 forwards an FMU's log messages, errors included, only while the host
has debug logging on (``loggingOn`` of fmi2Instantiate, or fmi2SetDebugLogging). In
the binary fmukit builds (``binary.FIXED``: known layout, by SHA-256) the flag is read
where that layout puts it; with any other binary it cannot be trusted, and the host
is taken not to hear: every error also goes to standard error (``fmukit.hostlog``).
"""
from __future__ import annotations

import ctypes
from typing import Any

from ..hostlog import HostLog, known_binary
from .binary import FIXED


def host_log(kwargs: dict[str, Any]) -> HostLog:
    """The slave's ``HostLog`` from pythonfmu's keywords (no ``logger``: a host in this
    process)."""
    logger = kwargs.get("logger")
    known = known_binary(logger, kwargs.get("resources"), FIXED)
    flag = None if known is None else ctypes.c_bool.from_address(logger
                                                                  + known.debug_flag_offset)
    return HostLog(flag, in_process="logger" not in kwargs, unknown=False)
