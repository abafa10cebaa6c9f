"""FMI 3.0 through pythonfmu3 0.3.4, and what fmukit owes to its defects (under ``ACTIVE``):
references released once per exception (``fmukit.entry``), every exception fmi3Fatal
(``Fmi3Entry.do_step`` returns fmi3Error), log messages forwarded whatever ``loggingOn``
(``Fmi3Entry.log``), a double free at exit (``KNOWN_BINARIES``), units, ranges, exact starts,
dependencies and the instance-only description, author, default experiment (``slave``)."""
from pythonfmu3 import __version__ as PYTHONFMU_VERSION

from ..entry import Binary

ACTIVE = PYTHONFMU_VERSION == "0.3.4"         # the version whose defects these are
# Its x86_64-linux binary, where fmubuild fixes its exit; its logger keeps the host's
# logging flag, which it never reads (another's host hears all).
# jmp finalizePythonInterpreter@plt  ->  ret. cppfmu::Logger holds its environment, its
# callback and a shared_ptr<Settings>, whose pointer is 16 bytes into the logger;
# Settings::debugLoggingEnabled, its first byte, is set from loggingOn.
KNOWN_BINARIES = {
    "53fd71ba834c18dea2df15d7e67b3a42441e7a607757cb5ac825ff98b505b580": Binary(  # 0.3.4
        0x16B80, bytes.fromhex("e9ebbfffff"), bytes.fromhex("c3ebbfffff"),
        "c26089da0282cd0e2fedcff896efb7379052cb4588a10cc26e013e3700ed4b05", 16,
        through_pointer=True),
}
