"""pythonfmu 0.7.0's linux64 binary as fmukit knows it: where to fix it, and its logger's layout.

``fmubuild.exit_fix`` patches the binary when an FMU is built (its exit-time heap
corruption); ``hostlog`` reads the host's debug-logging flag where this layout says
it is, in a binary it recognises by SHA-256.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Binary:
    """A pythonfmu binary fmukit knows inside out."""

    offset: int                 # file offset of onLibraryUnload
    code: bytes                 # its first instructions
    patched: bytes              # what they become
    fixed_sha256: str           # the binary once patched
    debug_flag_offset: int      # of PyLogger::debugLogging_, from the logger's address


# endbr64; jmp finalizePythonInterpreter  ->  endbr64; ret. PyLogger::log tests
# ``cmpb $0x0, 0x8(%rdi)``: the debug-logging flag sits 8 bytes into the logger.
KNOWN_BINARIES = {
    "4be156a552c16f30eb4395805c59855d8d4086056d0f165442565f6c5fbac0c9": Binary(  # 0.7.0
        0x16F30, bytes.fromhex("f30f1efae937dcffff"), bytes.fromhex("f30f1efac337dcffff"),
        "7b771dc338b6e8ecc6a7c658f8a409e30e14e4031b61d1cfc682f3b61451ed3e", 8),
}
FIXED = {b.fixed_sha256: b for b in KNOWN_BINARIES.values()}
"""The binaries as fmukit builds them, by their SHA-256."""
