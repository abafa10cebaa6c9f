"""Many runs of one course-keeping system at once: the batch route of sweeps and scorecards.

Why it exists: a sweep's runs differ only in their settings (seed, sea state, gains, gear,
route), and one run at a time pays the models' Python per step and per run. The batch
kernel steps M members in lockstep, each state an (M,) array, the wave components an
(M, N) array, so a step costs a few hundred numpy calls for all members together. It is
the one exception to "never write an equation twice": ``kernel`` writes the vessel,
guidance and autopilot equations again on arrays, operation for operation in the scalar
models' order, and the tests pin every recorded signal of every member to the scalar
route bit for bit. Every constant, parameter check and design computation is the scalar
models' own: each member is initialised by the in-process master (``members``), and the
kernel reads the models it built.

``simulate_members(system, overrides)`` returns one recording per member, as the
in-process route's ``Master.run`` would, holding the signals the figures of merit need
(``SIGNALS``). A member the kernel does not cover (``members.coverage``), or one that
fails (refused, non-finite), runs on the in-process route instead, alone, so that its
recording, error message included, is that route's; it never changes another member's
bits. ``selftest`` checks once per process that this machine's numpy computes as the
scalar models do, and the route refuses itself where it does not.
"""
from .route import SIGNALS, simulate_members
from .selftest import selftest

__all__ = ["SIGNALS", "simulate_members", "selftest"]
