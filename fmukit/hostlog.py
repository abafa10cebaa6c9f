"""Whether the host hears an FMU's log messages, and standard error when it does not.

pythonfmu 0.7 forwards an FMU's log messages, errors included, only while the host
has debug logging on, and pythonfmu3 0.3.4 forwards them whether or not the host
asked for them (``loggingOn``): a host that leaves logging off (fmpy's command line)
would never learn why a call failed, or would get messages it did not ask for. The
FMU's Python side is handed the address of pythonfmu's C++ logger (keyword
``logger``), which holds the host's flag; where it lies is the adapter's to say
(``hostlog`` of ``fmukit.pythonfmu07`` and ``fmukit.pythonfmu3_03``), in the binary
fmukit builds, recognised by its SHA-256 (``known_binary``). An error goes to the
host's logger when it listens, and to standard error when it does not, never to both.
Where the flag cannot be found, the adapter says whether its pythonfmu forwards.
"""
from __future__ import annotations

import ctypes
import hashlib
import sys
from pathlib import Path
from typing import TypeVar

from .refusals import naming

Known = TypeVar("Known")


def known_binary(logger: int | None, resources: str | None,
                 fixed: dict[str, Known]) -> Known | None:
    """What ``fixed`` (SHA-256: what fmukit knows of that binary) says of the FMU's binary
    beside ``resources``; None without a logger or a known binary."""
    if not logger or not resources:
        return None
    for binary in (Path(resources).parent / "binaries").glob("*/*"):
        try:
            known = fixed.get(hashlib.sha256(binary.read_bytes()).hexdigest())
        except OSError:
            continue
        if known is not None:
            return known
    return None


class HostLog:
    """Where an FMU's errors reach its user: the host's logger, or standard error.

    ``flag``: the host's logging flag, where the adapter found it; ``unknown``: whether
    the host hears the FMU where it did not; ``in_process``: a Python host that drains
    the log queue itself."""

    def __init__(self, flag: ctypes.c_bool | None, in_process: bool, unknown: bool):
        self._flag, self._in_process, self._unknown = flag, in_process, unknown
        self._told = ""

    def hears(self) -> bool:
        """Whether the host receives this FMU's log messages now."""
        if self._in_process:
            return True
        return bool(self._flag.value) if self._flag is not None else self._unknown

    def tell(self, instance_name: str, message: str) -> None:
        """Write an error to standard error if the host will not hear it; once, not again
        for each following call that fails for the same reason."""
        if not self.hears() and message != self._told:
            sys.stderr.write(naming(instance_name, message) + "\n")   # one write: hosts
            sys.stderr.flush()                              # step FMUs in parallel threads
            self._told = message
