"""``Refused``: how an FMU refuses a call, with a message and its cause as data.

The cause reaches the host as the log category ``fmukit.<cause>``, so a host tells a bad
parameter from a NaN input without reading the message. An exception of the model's own
code is located at its innermost frame in the user's code (``explain``).
"""
from __future__ import annotations

import functools
import sys
import sysconfig
import traceback
from pathlib import Path

CAUSES = {
    "parameter": "a parameter is invalid (refused at exitInitializationMode, failing the FMU)",
    "input": "an input is outside its declared range",
    "nonfinite_input": "an input is NaN or infinite (often another FMU's failure)",
    "step": "the communication step or time is out of range",
    "call": "a call the FMI standard does not allow now, or of the wrong type",
    "model": "the model raised an exception",
    "interrupted": "a signal (Ctrl-C, SIGTERM) arrived while the FMU computed",
}
"""Every cause, and what it means: the LogCategories ``fmukit.<cause>``."""


class Refused(ValueError):
    """A call the FMU refuses; the host gets a failed status, this message, and its cause."""

    def __init__(self, message: str, cause: str = "model", variable: str | None = None):
        if cause not in CAUSES:
            raise ValueError(f"unknown cause {cause!r} of a refusal; known: {', '.join(CAUSES)}")
        super().__init__(message)
        self.cause, self.variable = cause, variable

    @property
    def category(self) -> str:
        """The log category the host reads the cause from."""
        return f"fmukit.{self.cause}"


def explain(error: BaseException) -> str:
    """A refusal's message, or where the model's exception was raised, its type and message
    ('my_autopilot.py:42 in step: ZeroDivisionError: float division by zero'): the innermost
    frame in the user's code (else of all), its file relative to its folder on sys.path."""
    if isinstance(error, Refused):
        return str(error)
    frames = traceback.extract_tb(error.__traceback__)
    if not frames:
        return f"{type(error).__name__}: {error}"
    frame = next((f for f in reversed(frames) if _users(f.filename)), frames[-1])
    path = Path(frame.filename).resolve()
    inside = [r for r in (Path(p or ".").resolve() for p in sys.path) if r in path.parents]
    where = path.relative_to(max(inside, key=lambda r: len(r.parts))) if inside else path.name
    return f"{where}:{frame.lineno} in {frame.name}: {type(error).__name__}: {error}"


@functools.cache
def _not_users() -> tuple[Path, ...]:
    """Folders of code that is not the user's: the standard library, the installed
    packages (numpy, pythonfmu) and fmukit itself."""
    paths = sysconfig.get_paths()
    return (*{Path(paths[k]).resolve() for k in ("stdlib", "platstdlib", "purelib", "platlib")},
            Path(__file__).resolve().parent)


def _users(filename: str) -> bool:
    path = Path(filename).resolve()
    return not filename.startswith("<") and not any(f in path.parents for f in _not_users())


def naming(instance_name: str, text: str) -> str:
    """A message as it leaves the FMU: naming the FMU, for hosts whose logs do not
    (libcosim's shows neither the instance nor the call; standard error nothing)."""
    return f"{instance_name}: {text}"
