"""Eq (19) over a recorded run: J = psi_E + lambda sum(delta^2), lambda bringing both terms
to one level, calibrated once on calm_pd and held (``tests/test_cosim.py`` checks it)."""
from __future__ import annotations

from dataclasses import dataclass

from ..core.recording import Recording
from .metrics import cost_terms

LAMBDA = 1.8649470947066942     # psi_E / sum(delta^2) of calm_pd: 100.175 / 53.715 rad^2


@dataclass(frozen=True)
class Cost:
    """Eq (19) over the recorded samples."""
    psi_E: float
    sum_delta2: float
    lam: float

    @property
    def delta_E(self) -> float:
        return self.lam * self.sum_delta2

    @property
    def J(self) -> float:
        return self.psi_E + self.delta_E


def cost(recording: Recording, lam: float = LAMBDA) -> Cost:
    """Eq (19) with Delta psi = psi_d - psi (wrapped) and delta the actual rudder."""
    return Cost(*cost_terms(recording["guidance.psi_d"], recording["ship.psi"],
                            recording["ship.delta"]), lam)
