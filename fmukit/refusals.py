"""``Refused``: how an FMU refuses a call, with a message and its cause as data (the log
category ``fmukit.<cause>``: a host tells a bad parameter from a NaN input without reading)."""
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


class Refused(ValueError):
    """A call the FMU refuses; the host gets a failed status, this message, and its cause."""

    def __init__(self, message: str, cause: str = "model", variable: str | None = None):
        if cause not in CAUSES:
            raise ValueError(f"unknown cause {cause!r} of a refusal; known: {', '.join(CAUSES)}")
        super().__init__(message)
        self.cause, self.variable = cause, variable

    @property
    def category(self) -> str:
            return f"fmukit.{self.cause}"


def explain(error: BaseException) -> str:
    """A refusal's message, or the model's exception located at its innermost frame in the
    user's code ('my_autopilot.py:42 in step: ZeroDivisionError: float division by zero')."""
    if isinstance(error, Refused):
        return str(error)
    frames = traceback.extract_tb(error.__traceback__)
    said = f"{type(error).__name__}: {error}" if str(error) else type(error).__name__
    if not frames:
        return said
    frame = next((f for f in reversed(frames) if _users(f.filename)), frames[-1])
    path = Path(frame.filename).resolve()
    inside = [r for r in (Path(p or ".").resolve() for p in sys.path) if r in path.parents]
    where = path.relative_to(max(inside, key=lambda r: len(r.parts))) if inside else path.name
    return f"{where}:{frame.lineno} in {frame.name}: {said}"


@functools.cache
def _not_users() -> tuple[Path, ...]:
    """Folders of code not the user's: the standard library, installed packages, fmukit."""
    paths = sysconfig.get_paths()
    return (*{Path(paths[k]).resolve() for k in ("stdlib", "platstdlib", "purelib", "platlib")},
            Path(__file__).resolve().parent)


def _users(filename: str) -> bool:
    path = Path(filename).resolve()
    return not filename.startswith("<") and not any(f in path.parents for f in _not_users())


def naming(instance_name: str, text: str) -> str:
    """A message as it leaves the FMU, naming it (libcosim's log and standard error do not)."""
    return f"{instance_name}: {text}"
