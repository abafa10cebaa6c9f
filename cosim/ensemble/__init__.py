"""The batch route: M members of one course-keeping system stepped in lockstep on (M,) arrays,
op for op as the scalar models, so bit for bit the in-process route's (docs/performance.md)."""
from .route import SIGNALS, selftest, simulate_members

__all__ = ["SIGNALS", "simulate_members", "selftest"]
