"""FMI 2.0 through pythonfmu 0.7.0, and what fmukit owes to its defects (under ``ACTIVE``):
references released once per exception (``fmukit.entry``) and the entry module's namespace
once per instantiation (``slave.hold_namespace``), log messages forwarded only under debug
logging (``fmukit.entry.HostLog``), a heap corrupted at exit (``KNOWN_BINARIES``), units,
ranges and dependencies left out of modelDescription.xml (``slave``)."""
from pythonfmu import __version__ as PYTHONFMU_VERSION

from ..entry import Binary

ACTIVE = PYTHONFMU_VERSION == "0.7.0"         # the version whose defects these are
# Its linux64 binary, where fmubuild fixes its exit (another binary's host is taken not
# to hear): endbr64; jmp finalizePythonInterpreter  ->  endbr64; ret. PyLogger::log tests
# ``cmpb $0x0, 0x8(%rdi)``: the debug-logging flag sits 8 bytes into the logger.
KNOWN_BINARIES = {
    "4be156a552c16f30eb4395805c59855d8d4086056d0f165442565f6c5fbac0c9": Binary(  # 0.7.0
        0x16F30, bytes.fromhex("f30f1efae937dcffff"), bytes.fromhex("f30f1efac337dcffff"),
        "7b771dc338b6e8ecc6a7c658f8a409e30e14e4031b61d1cfc682f3b61451ed3e", 8),
}
