"""The monolithic reference of the accuracy study (``coupling_error``): guidance, autopilot
and ship as one ODE, with the controller inside the solver."""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from fmukit.timebase import communication_point, step_count
from ship_fmu.steering_gear import rudder_target
from ship_fmu.thrusters import actuator_model

from ..core.master import Master
from ..ensemble.members import COMPONENTS, initialise
from .integration_error import H

METHOD = "LSODA"
"""Stiff where the servo slews, not elsewhere: LSODA switches between Adams and BDF."""
MAX_STEP = 1.0
"""s: longer steps could pass through a circle of acceptance and miss its event."""
SERVO_GAIN = 1000.0
"""1/s: the steering gear as a stiff servo."""


def monolithic(system, stop_time: float | None = None, servo_gain: float = SERVO_GAIN,
               tolerance: float = 1e-9) -> dict[str, np.ndarray]:
    """Guidance, autopilot and ship as one ODE, the controller evaluated at every stage of
    the solver as a continuous Simulink block would be; sampled every 0.1 s like the
    master's rows.

    State: the ship's (x, y, psi, u, v, r, xi), the rudder angle delta and, for the SMC,
    its reference model (psi_z, r_z). The steering gear is delta' = clip(k (sat(delta_c) -
    delta), +-delta_rate_max), k = ``servo_gain``: it slews at the rate limit as the FMU's
    does, else lags the command by 1/k. A waypoint switch (the circle of acceptance reached,
    or the leg's end passed) is an event: the solver stops, switches the leg and restarts.
    The SMC's eq (42) tanh boundary layer is continuous: no event.
    """
    with Master(system, backend="inprocess") as master:
        member = initialise(master, {}, 0)
    guidance, autopilot, ship = (member.models[n] for n in COMPONENTS)
    forces = actuator_model(ship.actuators, *member.shafts)
    p = ship.params
    smc = hasattr(autopilot, "r_z_dot")
    stop = system.stop_time if stop_time is None else stop_time
    grid = np.array([communication_point(0.0, k, H) for k in range(step_count(0.0, stop, H) + 1)])

    def rhs(t: float, Y: np.ndarray, leg: int) -> list[float]:
        psi_d = guidance.course(leg)
        if smc:
            autopilot.psi_z, autopilot.r_z = Y[8], Y[9]
        delta_c = autopilot.command(Y[2], Y[5], psi_d)
        target = rudder_target(delta_c, p.delta_max)
        delta_dot = min(max(servo_gain * (target - Y[7]), -p.delta_rate_max), p.delta_rate_max)
        rates = [*ship.rates(t, tuple(Y[:7]), forces(Y[7])), delta_dot]
        if smc:
            rates += [Y[9], autopilot.r_z_dot(psi_d, Y[8], Y[9])]
        return rates

    def arrival(leg: int):
        (x0, y0), (x1, y1) = guidance.points[leg], guidance.points[leg + 1]
        length = math.hypot(x1 - x0, y1 - y0)

        def inside(t, Y, leg):
            return math.hypot(x1 - Y[0], y1 - Y[1]) - guidance.R_accept

        def past(t, Y, leg):
            return ((Y[0] - x0) * (x1 - x0) + (Y[1] - y0) * (y1 - y0)) / length - length

        for event in (inside, past):
            event.terminal, event.direction = True, 0.0
        return [inside, past]

    Y = [ship.x, ship.y, ship.psi, ship.u, ship.v, ship.r, ship.xi, ship.delta]
    if smc:
        Y += [autopilot.psi_z, autopilot.r_z]
    leg, finished, t = guidance.leg, guidance.finished, 0.0
    sampled: dict[float, tuple[np.ndarray, int]] = {}      # grid time: (state, leg)
    while True:
        events = [] if finished else arrival(leg)
        solution = solve_ivp(rhs, (t, stop), Y, method=METHOD, rtol=tolerance,
                             atol=tolerance, dense_output=True, events=events, args=(leg,),
                             max_step=MAX_STEP)
        end = solution.t[-1]
        for g in grid[(grid >= t) & (grid <= end)]:
            sampled.setdefault(float(g), (solution.sol(g), leg))
        if solution.status != 1:                 # the stop time, not an event
            break
        t, Y = end, solution.y[:, -1]
        if leg + 2 < len(guidance.points):
            leg += 1
        else:
            finished = True
    times = sorted(sampled)
    values = np.array([sampled[g][0] for g in times])
    return {"t": np.array(times),
            "psi_d": np.array([guidance.course(sampled[g][1]) for g in times]),
            "psi": values[:, 2], "r": values[:, 5], "x": values[:, 0], "y": values[:, 1],
            "delta": values[:, 7]}

