"""The ship run alone under a rudder program, in-process: a standard manoeuvre's trial."""
from __future__ import annotations

from dataclasses import replace

from fmukit.timebase import step_count

from .manoeuvres import RudderProgram
from .vessel import Vessel, VesselParameters

DT = 0.1                        # s, as the co-simulated manoeuvres


def trial(program: RudderProgram, t_end: float, params: VesselParameters) -> dict[str, list]:
    """x, y, psi, u, v, r and the program's reversals at each step's start, from straight
    running at the origin along x."""
    vessel = Vessel(replace(params, x0=0.0, y0=0.0, psi0=0.0))
    track = {name: [] for name in ("x", "y", "psi", "u", "v", "r", "reversals")}
    for k in range(step_count(0.0, t_end, DT)):
        delta_c = program.command(vessel.psi)
        program.update(vessel.psi)
        for name in track:
            source = program if name == "reversals" else vessel
            track[name].append(getattr(source, name))
        vessel.step(k * DT, DT, delta_c)
    return track
