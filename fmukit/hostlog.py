"""Whether the host hears an FMU's log messages, and standard error when it does not.

pythonfmu 0.7 forwards messages only while the host has debug logging on; pythonfmu3 0.3.4
forwards them whatever the host asked. ``HostLog`` finds the host's flag in pythonfmu's C++
logger, in a binary the adapter knows by SHA-256 (its ``binary.KNOWN_BINARIES``); an error
then reaches the host's logger or standard error, never both.
"""
from __future__ import annotations

import ctypes
import hashlib
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .refusals import naming


@dataclass(frozen=True)
class Binary:
    """A pythonfmu binary fmukit knows inside out."""

    offset: int                 # file offset of onLibraryUnload
    code: bytes                 # its first instructions
    patched: bytes              # what they become (fmubuild.exit_fix)
    fixed_sha256: str           # the binary once patched
    logger_offset: int          # where the host's logging flag is, from the logger
    through_pointer: bool = False   # there is a pointer to the flag instead

    def flag(self, logger: int) -> ctypes.c_bool | None:
        """The host's logging flag in the logger at address ``logger``."""
        address = logger + self.logger_offset
        if self.through_pointer:
            address = ctypes.c_void_p.from_address(address).value
        return ctypes.c_bool.from_address(address) if address else None


def known_binary(logger: int | None, resources: str | None,
                 known_binaries: dict[str, Binary]) -> Binary | None:
    """The binary of ``known_binaries``, as fmukit builds it, beside ``resources``; None
    without a logger or a known binary."""
    if not logger or not resources:
        return None
    fixed = {b.fixed_sha256: b for b in known_binaries.values()}
    for binary in (Path(resources).parent / "binaries").glob("*/*"):
        try:
            known = fixed.get(hashlib.sha256(binary.read_bytes()).hexdigest())
        except OSError:
            continue
        if known is not None:
            return known
    return None


class HostLog:
    """Where an FMU's errors reach its user: the host's logger (by its flag, where found;
    else ``unknown``; always in the host's process), or standard error."""

    def __init__(self, kwargs: dict[str, Any], known_binaries: dict[str, Binary],
                 unknown: bool):
        """From pythonfmu's keywords (without a ``logger``: a host in this process)."""
        logger = kwargs.get("logger")
        known = known_binary(logger, kwargs.get("resources"), known_binaries)
        self._flag = None if known is None else known.flag(logger)
        self._in_process, self._unknown = "logger" not in kwargs, unknown
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
