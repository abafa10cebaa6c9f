"""The FMI 2.0 co-simulation call sequence: which call is allowed in which phase.

    instantiated --fmi2EnterInitializationMode--> initialization
                 --fmi2ExitInitializationMode--> step --fmi2Terminate--> terminated

fmi2Reset returns to instantiated (pythonfmu makes a new slave object for it).
"""
from __future__ import annotations

from .refusals import Refused
from .variables import Var

_AFTER = {"instantiated": "fmi2Instantiate or fmi2Reset",
          "initialization": "fmi2EnterInitializationMode",
          "step": "fmi2ExitInitializationMode", "terminated": "fmi2Terminate"}


class CallSequence:
    """The phase of one FMU instance and the rules of the standard for it."""

    def __init__(self, phase: str = "instantiated"):
        self.phase = phase

    def require(self, call: str, *phases: str) -> None:
        """Refused naming the call and the phase unless the phase is one of ``phases``."""
        if self.phase not in phases:
            raise Refused(f"{call} is not allowed in phase '{self.phase}' (FMI 2.0 allows "
                          f"it after {' or '.join(_AFTER[p] for p in phases)})", "call")

    def step_refusal(self) -> str | None:
        """Why fmi2DoStep is not allowed now, or None if it is."""
        if self.phase != "step":
            return (f"doStep called in phase '{self.phase}': "
                    "call exitInitializationMode first, and not after terminate")
        return None

    def check_settable(self, var: Var) -> None:
        """Refused naming ``var`` if the standard forbids setting it now."""
        if var.causality == "output":
            raise Refused(f"{var.name} is an output and cannot be set", "call", var.name)
        if var.causality == "parameter" and self.phase not in ("instantiated",
                                                               "initialization"):
            raise Refused(f"parameter {var.name} is fixed after initialisation "
                          f"(phase '{self.phase}')", "call", var.name)
        if self.phase == "terminated":
            raise Refused(f"cannot set {var.name} after terminate", "call", var.name)
