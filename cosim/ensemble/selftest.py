"""Whether this machine's numpy computes as the scalar models do: checked once per process.

The kernel relies on numpy's element-wise sin, cos, sqrt and arithmetic giving the C
library's bits, and on its sums over the wave components adding in the scalar model's
order. That held on the machines measured (docs/performance.md), but numpy dispatches
its loops by CPU, so each process checks it before its first batch: a short run per
autopilot (PD, PID, both sliding-mode readings), in calm water and in waves, with the
rudder on its stops, a route that switches legs and a heading across +-180 deg, through
the kernel and through the scalar models, every signal of every step compared to the bit.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from autopilot_fmu.design import design_model
from autopilot_fmu.guidance import WaypointGuidance
from autopilot_fmu.pd import PDAutopilot
from autopilot_fmu.smc import SlidingModeAutopilot, SlidingModeDesign
from ship_fmu.vessel import N_PROPELLER, Vessel, VesselParameters

from .reference import SIGNALS, step_models

STEPS, H = 100, 0.1
"""10 s: within it the members of every autopilot switch legs and cross +-180 deg, and in
waves some of every autopilot's reach a rudder stop (in calm water the PD's). The
self-test's time (about 0.6 s; 1.0 s over 20 s) is each worker's before its first batch."""
ROUTE = [(0.0, 0.0), (-1.5, 0.2), (-2.5, 2.5), (0.5, 3.0)]
"""A short route with turns beyond 90 deg, from a start heading near 180 deg."""


def _pilot(kind: str, psi0: float, member: int):
    if kind == "pd":
        return PDAutopilot(Kp=2.0 + member, Kd=50.0)
    if kind == "pid":
        from autopilot_fmu.pid_autopilot_slave import PIDAutopilot
        return PIDAutopilot(Ki=0.5, e_int=math.radians(90))
    design = SlidingModeDesign.from_model(design_model("paper", 0.3))
    return SlidingModeAutopilot(design, psi_z=psi0, equivalent_control=kind[4:])


def _members(kind: str, Hs: float) -> list[dict]:
    """Four members of one autopilot: seeds, headings near +-pi, gear rates."""
    out = []
    for member in range(4):
        psi0 = (-1.0) ** member * (math.pi - 0.01 * member)
        ship = Vessel(VesselParameters(psi0=psi0, Hs=Hs, wave_seed=member, T0=0.7 + 0.1 * member,
                                       delta_rate_max=math.radians(10.0 + 5.0 * member)))
        out.append({"guidance": WaypointGuidance(ROUTE, 0.5), "ship": ship,
                    "autopilot": _pilot(kind, psi0, member)})
    return out


@lru_cache(maxsize=1)
def selftest() -> str | None:
    """Why the batch kernel would not give the scalar models' bits here, or None."""
    from .members import Member
    from .route import _lockstep

    for kind in ("pd", "pid", "smc_paper", "smc_tracking"):
        for Hs in (0.0, 0.02):
            batch = [Member(models, (N_PROPELLER, N_PROPELLER, 0.0), {"backends": {}})
                     for models in _members(kind, Hs)]
            recordings = _lockstep(list(enumerate(batch)), 0.0, H, STEPS, SIGNALS,
                                   {s: "" for s in SIGNALS})
            for (i, recording), models in zip(recordings, _members(kind, Hs)):
                scalar = step_models(models["guidance"], models["autopilot"], models["ship"],
                                     (N_PROPELLER, N_PROPELLER, 0.0), 0.0, H, STEPS)
                for signal in SIGNALS:
                    ours = recording[signal] if recording is not None else np.full(STEPS + 1, 0.0)
                    differ = ours.tobytes() != scalar[signal].tobytes()
                    if recording is None or differ:
                        where = "failed" if recording is None else (
                            f"{signal} differs from step "
                            f"{int(np.flatnonzero(ours != scalar[signal])[0])}")
                        return (f"on this machine the batch kernel does not compute as the "
                                f"scalar models ({kind}, Hs = {Hs} m, member {i}: {where}); "
                                "numpy's array functions round differently here")
    return None
