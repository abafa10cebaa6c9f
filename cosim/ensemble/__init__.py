"""Many runs of one course-keeping system at once: the batch route of sweeps and scorecards.

The kernel steps M members in lockstep, each state an (M,) array, writing the vessel,
guidance and autopilot equations again on arrays, operation for operation in the scalar
models' order; the tests pin every signal of every member to the in-process route bit for
bit. Each member is initialised by the in-process master (``members``). A member the kernel
does not cover (``members.coverage``), or one that fails, runs alone on the in-process route;
``selftest`` checks once per process that this machine's numpy computes as the scalar models.
"""
from .route import SIGNALS, selftest, simulate_members

__all__ = ["SIGNALS", "simulate_members", "selftest"]
