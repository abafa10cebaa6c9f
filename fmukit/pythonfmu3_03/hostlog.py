"""The host's logging flag in pythonfmu3 0.3.4's logger, which the logger itself never reads.

pythonfmu3 forwards every message but a debug one to the host, whatever the host asked
with ``loggingOn`` of fmi3InstantiateCoSimulation or fmi3SetDebugLogging
(``cppfmu::Logger::Log`` does not test it; only ``DebugLog`` does). FMI 3.0 says an FMU
does not call the host's logMessage while logging is off. In the binary fmukit builds
(``binary.FIXED``, by SHA-256) the flag is read where the logger keeps it
(``Logger::m_settings->debugLoggingEnabled``), so that the FMU holds its messages back
while it is off (``slave.Fmi3Entry.log``) and tells its errors on standard error
instead (``fmukit.hostlog``). With any other binary the flag is unknown, and the host
is taken to hear: pythonfmu3 forwards.
"""
from __future__ import annotations

import ctypes
from typing import Any

from ..hostlog import HostLog, known_binary
from .binary import FIXED


def host_log(kwargs: dict[str, Any]) -> HostLog:
    """The slave's ``HostLog`` from pythonfmu3's keywords (no ``logger``: a host in this
    process)."""
    logger, flag = kwargs.get("logger"), None
    known = known_binary(logger, kwargs.get("resources"), FIXED)
    if known is not None:
        settings = ctypes.c_void_p.from_address(logger + known.settings_offset).value
        flag = ctypes.c_bool.from_address(settings) if settings else None
    return HostLog(flag, in_process="logger" not in kwargs, unknown=True)
