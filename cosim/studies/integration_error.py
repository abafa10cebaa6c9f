"""The accuracy study's part 1 (docs/reproduction.md): the ship (``Vessel``) under a rudder
program held over each 0.1 s step, by its RK4 at several h_max, against DOP853 restarted at
each communication point and each kink of the steering gear's response."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_ivp

from fmukit.timebase import communication_point, step_count
from ship_fmu.manoeuvres import RudderProgram
from ship_fmu.steering_gear import RudderMotion
from ship_fmu.thrusters import actuator_model
from ship_fmu.vessel import N_PROPELLER, Vessel, VesselParameters

from . import table

H = 0.1                                       # s, the communication step (of parts 2-3 too)
H_MAX = (0.1, 0.05, 0.025)                    # s, the RK4 steps compared
STATES = ("psi", "r", "x", "y")
TOLERANCE = 1e-12


def commands(program: str, t_end: float = 400.0) -> np.ndarray:
    """The rudder command held over each communication step, rad."""
    times = [communication_point(0.0, k, H) for k in range(step_count(0.0, t_end, H))]
    if program == "step":
        return np.full(len(times), math.radians(20.0))
    if program == "sine":
        return np.array([math.radians(10.0) * math.sin(2.0 * math.pi * t / 30.0) for t in times])
    if program == "zigzag":
        rudder, vessel, out = RudderProgram(math.radians(20.0), math.radians(20.0)), Vessel(), []
        for t in times:
            out.append(rudder.command(vessel.psi))
            rudder.update(vessel.psi)
            vessel.step(t, H, out[-1])
        return np.array(out)
    raise ValueError(f"program must be step, sine or zigzag, got {program!r}")


def rk4(delta_c: np.ndarray, h_max: float) -> dict[str, np.ndarray]:
    """The FMU's model: RK4 at ``h_max``; each signal at every communication point."""
    vessel = Vessel(VesselParameters(h_max=h_max))
    rows = [[getattr(vessel, s) for s in STATES]]
    for k, command in enumerate(delta_c):
        vessel.step(communication_point(0.0, k, H), H, float(command))
        rows.append([getattr(vessel, s) for s in STATES])
    return dict(zip(STATES, np.array(rows).T))


def reference(delta_c: np.ndarray, tolerance: float = TOLERANCE) -> dict[str, np.ndarray]:
    """The same equations by DOP853, restarted at each communication point and kink."""
    vessel = Vessel()
    p = vessel.params
    forces = actuator_model(vessel.actuators, N_PROPELLER, N_PROPELLER, 0.0)
    y = np.array([vessel.x, vessel.y, vessel.psi, vessel.u, vessel.v, vessel.r, vessel.xi])
    delta = vessel.delta
    rows = [[y[2], y[5], y[0], y[1]]]
    for k, command in enumerate(delta_c):
        t = communication_point(0.0, k, H)
        gear = RudderMotion(delta, float(command), p.delta_max, p.delta_rate_max)
        pieces = [(0.0, gear.reach), (gear.reach, H)] if 0.0 < gear.reach < H else [(0.0, H)]

        def f(s: float, state: np.ndarray, t=t, gear=gear) -> list[float]:
            return list(vessel.rates(t + s, tuple(state), forces(gear(s))))

        for a, b in pieces:
            y = solve_ivp(f, (a, b), y, method="DOP853", rtol=tolerance, atol=tolerance).y[:, -1]
        delta = gear(H)
        rows.append([y[2], y[5], y[0], y[1]])
    return dict(zip(STATES, np.array(rows).T))


class Error(NamedTuple):
    """Max and RMS error of one signal against the reference."""
    max: float
    rms: float


def errors(run: dict[str, np.ndarray], ref: dict[str, np.ndarray]) -> dict[str, Error]:
    """Each signal's ``Error`` against the reference."""
    e = {s: np.abs(run[s] - ref[s]) for s in STATES}
    return {s: Error(float(e[s].max()), float(np.sqrt(np.mean(e[s] * e[s])))) for s in STATES}


def orders(errors: list[float]) -> list[float]:
    """The observed orders of errors at steps halved in turn (pairs with a zero left out)."""
    return [math.log2(a / b) for a, b in zip(errors, errors[1:]) if a > 0 and b > 0]


def open_loop(program: str, t_end: float = 400.0) -> dict:
    """Errors of RK4 at each h_max, the observed orders, and the reference's own error."""
    delta_c = commands(program, t_end)
    ref = reference(delta_c)
    finer = reference(delta_c, TOLERANCE / 2)
    by_h = {h: errors(rk4(delta_c, h), ref) for h in H_MAX}
    return {"program": program, "errors": by_h,
            "orders": {s: orders([by_h[h][s].max for h in H_MAX]) for s in STATES},
            "reference_error": errors(finer, ref)}


def open_loop_table(results: list[dict]) -> str:
    """Part 1 as a Markdown table."""
    rows = []
    for result in results:
        program = result["program"]
        rows += [[program, f"{h:g}", *(f"{e[s].max:.2e} / {e[s].rms:.2e}" for s in STATES)]
                 for h, e in result["errors"].items()]
        rows += [[program, "order", *(", ".join(f"{o:.2f}" for o in result["orders"][s])
                                      for s in STATES)],
                 [program, "reference, tol / 2", *(f"{result['reference_error'][s].max:.1e}"
                                                   for s in STATES)]]
    return "\n".join(table(["program", "h_max (s)", *(f"max / RMS error {s}" for s in STATES)],
                           rows, 1))
