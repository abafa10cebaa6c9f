"""How an FMU refuses a call: ``Refused``, with a message for the user and its cause as data.

The cause travels to the host as the log message's category, ``fmukit.<cause>``
(declared in the model description's LogCategories), so that a host tells a bad
parameter from an input its neighbour made NaN without reading the message.
"""
from __future__ import annotations

CAUSES = {
    "parameter": "a parameter is invalid (refused at exitInitializationMode, failing the FMU)",
    "input": "an input is outside its declared range",
    "nonfinite_input": "an input is NaN or infinite (often another FMU's failure)",
    "step": "the communication step or time is out of range",
    "call": "a call the FMI 2.0 standard does not allow now, or of the wrong type",
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
    """What went wrong, for the user: a refusal's own message, or the exception's type and
    message."""
    return str(error) if isinstance(error, Refused) else f"{type(error).__name__}: {error}"


def naming(instance_name: str, text: str) -> str:
    """A message as it leaves the FMU: naming the FMU, for hosts whose logs do not
    (libcosim's shows neither the instance nor the call; standard error nothing)."""
    return f"{instance_name}: {text}"
