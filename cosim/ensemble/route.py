"""``simulate_members``: in lockstep where the kernel covers them, alone in-process where
not; ``selftest``, the kernel checked on this machine against the scalar models."""
from __future__ import annotations

import math
import time
from collections import defaultdict
from functools import lru_cache
from typing import Any, Callable, Sequence

import numpy as np

from autopilot_fmu.design import design_model
from autopilot_fmu.guidance import WaypointGuidance
from autopilot_fmu.pd import PDAutopilot
from autopilot_fmu.smc import SlidingModeAutopilot, SlidingModeDesign
from fmukit.autopilot import INPUTS
from fmukit.numerics import substeps
from fmukit.timebase import communication_point
from ship_fmu.vessel import N_PROPELLER, Vessel, VesselParameters

from ..core.master import Master
from ..core.recording import Recording, check_signals, require_memory
from ..core.ssd import SystemDescription
from ..core.watchdog import no_limit
from .control import KINDS, GuidanceArrays
from .reference import COMPONENTS, SIGNALS as ALL_SIGNALS, Member, coverage, initialise, step_models
from .vessel import VesselArrays


class TimeLimit(RuntimeError):
    """A time limit passed (``beat`` said so): the batch stops."""


SIGNALS = ("guidance.psi_d", "guidance.wp_index", "ship.x", "ship.y", "ship.psi",
           "ship.delta")                           # what ``studies.merit.run_metrics`` needs
R_MAX = next(var.max for var in INPUTS if var.name == "r")   # rad/s: beyond, autopilots refuse


def simulate_members(system: SystemDescription, overrides: Sequence[dict[str, dict[str, Any]]],
                     stop_time: float | None = None, signals: Sequence[str] = SIGNALS,
                     beat: Callable[[str | float], str | None] = no_limit) -> list[Recording]:
    """One recording per member with ``overrides[i]``, as in-process ``Master.run`` records
    it, of ``signals``; ValueError naming a refused member before anything runs; TimeLimit
    where ``beat`` (``Watchdog.beat``, before each initialisation and step) gives a reason."""
    with Master(system, backend="inprocess") as master:
        check_signals(signals, master.columns)              # in the in-process route's words
        for i, member in enumerate(overrides):
            try:
                master.configure(member)
            except ValueError as error:
                raise ValueError(f"member {i}: {error}") from None
        _, h, n_steps = master.system.steps(stop_time)
        require_memory(n_steps + 1, len(signals) * len(overrides))   # as in-process refuses
        reason = coverage(system) or _unrecorded(signals) or selftest()
        recordings: dict[int, Recording] = {}
        groups: dict[tuple, list[tuple[int, Member]]] = defaultdict(list)
        for i, member_overrides in enumerate(overrides):
            _check(beat(f"initialising member {i} of the batch"))
            member = None if reason else initialise(master, member_overrides, n_steps)
            why = reason or _outside(member, h)
            if why:
                recordings[i] = _alone(master, member_overrides, stop_time, signals, why)
            else:       # stepped together: the same shafts, in calm water or N wave components
                waves = member.models["ship"].waves
                sea = None if waves is None else len(waves.components.omega)
                groups[sea, member.shafts].append((i, member))
        for members in groups.values():
            for i, recording in lockstep(members, system.start_time, h, n_steps, signals,
                                         master.units, beat):
                recordings[i] = recording or _alone(
                    master, overrides[i], stop_time, signals,
                    "it failed in the batch kernel, and ran alone to say why")
    return [recordings[i] for i in range(len(overrides))]


def _check(expired: str | None) -> None:
    if expired:
        raise TimeLimit(expired)


def _unrecorded(signals: Sequence[str]) -> str | None:
    others = [s for s in signals if s not in ALL_SIGNALS]
    return f"the batch kernel records no {', '.join(others)}" if others else None


def cut(ship: Vessel, h: float) -> str | None:
    """Why the kernel cannot step ``ship``: its h_max cuts the step (or None)."""
    return None if ship._cut_of(h)[0] == 1 else (
        f"ship.h_max = {ship.params.h_max} s cuts the {h} s step into RK4 sub-steps, which "
        "the batch kernel does not")


def _outside(member: Member | None, h: float) -> str | None:
    if member is None:
        return "its initialisation failed"
    pilot = member.models["autopilot"]
    if (why := cut(member.models["ship"], h)) is not None:
        return why
    if isinstance(pilot, SlidingModeAutopilot) and substeps(h, pilot._h_max, "") != 1:
        return (f"autopilot.omega_n = {pilot.omega_n} rad/s and zeta = {pilot.zeta} cut the {h} "
                "s step of the reference model (44) into RK4 sub-steps, which the batch kernel "
                "does not")
    return None


def _alone(master: Master, overrides: dict[str, dict[str, Any]], stop_time: float | None,
           signals: Sequence[str], why: str) -> Recording:
    master.reset()
    master.configure(overrides)
    recording = master.run(stop_time)
    recording.meta["notes"] = [*recording.meta.get("notes", []),
                               f"ran on the in-process route, not in the batch: {why}"]
    return recording.holding(signals)


def lockstep(members: list[tuple[int, Member]], t0: float, h: float, n_steps: int,
             signals: Sequence[str], units: dict[str, str],
             beat: Callable[[str | float], str | None] = no_limit
             ) -> list[tuple[int, Recording | None]]:
    """(index, recording) of the members stepped together; None where a signal went
    non-finite or the yaw rate left the autopilot's range."""
    started = time.perf_counter()
    models = [m.models for _, m in members]
    ship = VesselArrays([m["ship"] for m in models], members[0][1].shafts)
    guidance = GuidanceArrays([m["guidance"] for m in models])
    pilot = KINDS[type(models[0]["autopilot"]).__name__]([m["autopilot"] for m in models])
    block = np.empty((n_steps + 1, len(signals), len(members)))
    rows = [ALL_SIGNALS.index(s) for s in signals]
    failed = np.zeros(len(members), dtype=bool)
    with np.errstate(all="ignore"):                # a failing member's lanes only
        for k in range(n_steps + 1):
            t = communication_point(t0, k, h)
            _check(beat(t))
            psi_d, wp_index = guidance.outputs(ship.x, ship.y)
            delta_c = pilot.command(ship.psi, ship.r, psi_d)
            values = (psi_d, wp_index, delta_c, ship.x, ship.y, ship.psi, ship.u, ship.v,
                      ship.r, ship.delta)
            for j, row in enumerate(rows):
                block[k, j] = values[row]
            failed |= ~np.isfinite(np.add.reduce(values[2:]) + ship.xi) | (np.abs(ship.r) > R_MAX)
            if k == n_steps:
                break
            pilot.step(t, h, ship.psi, ship.r, psi_d)
            ship.step(t, h, delta_c)
    times = np.array([communication_point(t0, k, h) for k in range(n_steps + 1)])
    share = (time.perf_counter() - started) / len(members)
    return [(i, None if failed[j] else Recording(
        list(signals), times, block[:, :, j], n_steps + 1, units={s: units[s] for s in signals},
        meta={**member.meta, "backend": "batch", "backends": dict.fromkeys(
            member.meta["backends"], "batch"), "wall_time_s": share}))
        for j, (i, member) in enumerate(members)]


# -- the self-test: numpy dispatches its loops by CPU, so each process checks once that its
# sin, cos, sqrt, arithmetic and sums give the scalar models' bits (docs/performance.md).
STEPS, H = 100, 0.1     # 10 s: members switch legs, cross +-180 deg, some reach a stop
ROUTE = [(0.0, 0.0), (-1.5, 0.2), (-2.5, 2.5), (0.5, 3.0)]   # turns beyond 90 deg


def _members(kind: str, Hs: float) -> list[dict]:
    """Four members of ``kind``: headings either side of +-180 deg, gears, gains, seeds."""
    from autopilot_fmu.pid_autopilot_slave import PIDAutopilot

    out = []
    for member in range(4):
        psi0 = (-1.0) ** member * (math.pi - 0.01 * member)
        ship = Vessel(VesselParameters(psi0=psi0, Hs=Hs, wave_seed=member, T0=0.7 + 0.1 * member,
                                       delta_rate_max=math.radians(10.0 + 5.0 * member)))
        pilot = (PDAutopilot(Kp=2.0 + member, Kd=50.0) if kind == "pd" else
                 PIDAutopilot(Ki=0.5, e_int=math.radians(90)) if kind == "pid" else
                 SlidingModeAutopilot(SlidingModeDesign.from_model(design_model("paper", 0.3)),
                                      psi_z=psi0, equivalent_control=kind[4:]))
        out.append({"guidance": WaypointGuidance(ROUTE, 0.5), "ship": ship, "autopilot": pilot})
    return out


@lru_cache(maxsize=1)
def selftest() -> str | None:
    """Why the batch kernel would not give the scalar models' bits here, or None."""
    shafts = (N_PROPELLER, N_PROPELLER, 0.0)
    for kind in ("pd", "pid", "smc_paper", "smc_tracking"):
        for Hs in (0.0, 0.02):
            batch = [Member(models, shafts, {"backends": {}}) for models in _members(kind, Hs)]
            recordings = lockstep(list(enumerate(batch)), 0.0, H, STEPS, ALL_SIGNALS,
                                  dict.fromkeys(ALL_SIGNALS, ""))
            for (i, recording), models in zip(recordings, _members(kind, Hs)):
                scalar = step_models(*(models[n] for n in COMPONENTS), shafts, 0.0, H, STEPS)
                for signal in ALL_SIGNALS:
                    if recording is None or recording[signal].tobytes() != scalar[signal].tobytes():
                        where = "failed" if recording is None else (
                            f"{signal} differs from step "
                            f"{int(np.flatnonzero(recording[signal] != scalar[signal])[0])}")
                        return (f"on this machine the batch kernel does not compute as the "
                                f"scalar models ({kind}, Hs = {Hs} m, member {i}: {where}); "
                                "numpy's array functions round differently here")
    return None
