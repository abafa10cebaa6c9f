"""The co-simulation call sequence of FMI 2.0 and 3.0 alike: instantiated -> initialization
-> step -> terminated (reset makes a new slave). Calls are named as the version names them.
"""
from __future__ import annotations

from .refusals import Refused
from .variables import Var

_AFTER = {"instantiated": "{api}{instantiate} or {api}Reset",
          "initialization": "{api}EnterInitializationMode",
          "step": "{api}ExitInitializationMode", "terminated": "{api}Terminate"}
_INSTANTIATE = {"fmi2": "Instantiate", "fmi3": "InstantiateCoSimulation"}


class CallSequence:
    """The phase of one FMU instance and the rules of the standard (``api``: "fmi2" or
    "fmi3") for it."""

    def __init__(self, api: str, phase: str = "instantiated"):
        self.api, self.phase = api, phase

    def require(self, call: str, *phases: str) -> None:
        """Refused naming the call (``Terminate``: fmi2Terminate) and the phase unless the
        phase is one of ``phases``."""
        if self.phase not in phases:
            after = " or ".join(_AFTER[p].format(api=self.api, instantiate=_INSTANTIATE[self.api])
                                for p in phases)
            raise Refused(f"{self.api}{call} is not allowed in phase '{self.phase}' (FMI "
                          f"{self.api[3:]}.0 allows it after {after})", "call")

    def step_refusal(self) -> str | None:
        """Why doStep is not allowed now, or None if it is."""
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
