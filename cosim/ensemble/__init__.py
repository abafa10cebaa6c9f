"""The batch route of sweeps and scorecards: M members of one course-keeping system stepped
in lockstep on (M,) arrays, operation for operation in the scalar models' order (the tests pin
every signal to the in-process route bit for bit). A member not covered (``members.coverage``)
or failing runs alone in-process; ``selftest`` checks this machine's numpy once per process.
"""
from .route import SIGNALS, selftest, simulate_members

__all__ = ["SIGNALS", "simulate_members", "selftest"]
