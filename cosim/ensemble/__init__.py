"""The batch route: M members of one course-keeping system stepped in lockstep on (M,)
arrays, operation for operation as the scalar models, so bit for bit the in-process route's
(docs/performance.md); what the kernel does not cover runs alone in-process."""
from .route import SIGNALS, selftest, simulate_members

__all__ = ["SIGNALS", "simulate_members", "selftest"]
