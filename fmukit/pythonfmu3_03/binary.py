"""pythonfmu3 0.3.4's x86_64-linux binary as fmukit knows it: where to fix it, its logger's layout.

``fmubuild.exit_fix`` patches the binary when an FMU is built (its exit-time heap
corruption, as pythonfmu 0.7.0's); ``hostlog`` reads the host's logging flag where
this layout says it is, in a binary it recognises by SHA-256.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Binary:
    """A pythonfmu3 binary fmukit knows inside out."""

    offset: int                 # file offset of onLibraryUnload
    code: bytes                 # its first instruction
    patched: bytes              # what it becomes
    fixed_sha256: str           # the binary once patched
    settings_offset: int        # of the pointer to the logger's Settings, from the logger's
                                # address; Settings::debugLoggingEnabled is its first byte


# jmp finalizePythonInterpreter@plt  ->  ret. cppfmu::Logger holds its environment, its
# callback and a shared_ptr<Settings>, whose pointer is 16 bytes into the logger;
# fmi3InstantiateCoSimulation sets debugLoggingEnabled from loggingOn.
KNOWN_BINARIES = {
    "53fd71ba834c18dea2df15d7e67b3a42441e7a607757cb5ac825ff98b505b580": Binary(  # 0.3.4
        0x16B80, bytes.fromhex("e9ebbfffff"), bytes.fromhex("c3ebbfffff"),
        "c26089da0282cd0e2fedcff896efb7379052cb4588a10cc26e013e3700ed4b05", 16),
}
FIXED = {b.fixed_sha256: b for b in KNOWN_BINARIES.values()}
"""The binaries as fmukit builds them, by their SHA-256."""
