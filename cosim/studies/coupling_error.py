"""The accuracy study's parts 2 and 3 (docs/reproduction.md): the paper's runs by our master
at the 0.1 s step, Gauss-Seidel and Jacobi, against a monolithic reference with the controller
inside the solver, by the figures of eq (19); then J over communication steps."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from fmukit.timebase import communication_point, step_count
from ship_fmu.steering_gear import rudder_target
from ship_fmu.thrusters import actuator_model

from .. import scenarios
from ..analysis.metrics import LAMBDA, cost_terms
from ..core.master import Master
from ..ensemble.reference import COMPONENTS, initialise
from . import table
from .integration_error import H, orders

PAPER_RUNS = ("calm_pd", "calm_smc", "waves_pd", "waves_smc")
COUPLINGS = ("gauss-seidel", "jacobi")
STEPS = (0.4, 0.2, 0.1, 0.05, 0.025, 0.0125)   # s, communication steps of part 3
METHOD = "LSODA"        # stiff where the servo slews, not elsewhere: Adams and BDF in turn
MAX_STEP = 1.0          # s: a longer step could pass a circle of acceptance unseen
SERVO_GAIN = 1000.0     # 1/s: the steering gear as a stiff servo
TOLERANCE = 1e-9


def monolithic(system, stop_time: float | None = None) -> dict[str, np.ndarray]:
    """psi_d, psi and delta every 0.1 s of guidance, autopilot and ship as one ODE, the
    controller evaluated at every stage of the solver; the steering gear a stiff servo, a
    waypoint switch an event (docs/reproduction.md)."""
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
        delta_dot = min(max(SERVO_GAIN * (target - Y[7]), -p.delta_rate_max), p.delta_rate_max)
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

        inside.terminal = past.terminal = True
        return [inside, past]

    Y = [ship.x, ship.y, ship.psi, ship.u, ship.v, ship.r, ship.xi, ship.delta]
    if smc:
        Y += [autopilot.psi_z, autopilot.r_z]
    leg, finished, t = guidance.leg, guidance.finished, 0.0
    sampled: dict[float, tuple[np.ndarray, int]] = {}      # grid time: (state, leg)
    while True:
        events = [] if finished else arrival(leg)
        solution = solve_ivp(rhs, (t, stop), Y, method=METHOD, rtol=TOLERANCE,
                             atol=TOLERANCE, dense_output=True, events=events, args=(leg,),
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
    return {"psi_d": np.array([guidance.course(sampled[g][1]) for g in times]),
            "psi": values[:, 2], "delta": values[:, 7]}


def cosimulation(name: str, step: float, coupling: str,
                 stop_time: float | None = None) -> dict[str, np.ndarray]:
    """Our master in-process at ``step``, sampled on the 0.1 s grid (a coarser step at its
    own points, each ``weight`` samples)."""
    system = dataclasses.replace(scenarios.load(name), step_size=step)
    with Master(system, coupling=coupling, backend="inprocess") as master:
        recording = master.run(stop_time)
    every = max(1, round(H / step))
    return {"psi_d": recording["guidance.psi_d"][::every], "psi": recording["ship.psi"][::every],
            "delta": recording["ship.delta"][::every], "weight": max(1.0, step / H)}


def figures(run: dict[str, np.ndarray]) -> dict[str, float]:
    """psi_E, sum delta^2 and J of eq (19) on the 0.1 s grid."""
    weight = run.get("weight", 1.0)
    psi_E, sum_delta2 = (weight * f for f in cost_terms(run["psi_d"], run["psi"], run["delta"]))
    return {"psi_E": psi_E, "sum_delta2": sum_delta2, "J": psi_E + LAMBDA * sum_delta2}


def study(name: str, steps=STEPS, stop_time: float | None = None) -> dict[str, list[dict]]:
    """Parts 2 and 3 for one run: {"monolithic": [its figures], coupling: [the figures at each
    step, J's relative distance from the monolithic J and, at 0.1 s, psi's largest]}."""
    reference = monolithic(scenarios.load(name), stop_time)
    out = {"monolithic": [{"step": H, **figures(reference), "J_error": 0.0, "max_dpsi": 0.0}]}
    J = out["monolithic"][0]["J"]
    for coupling in COUPLINGS:
        out[coupling] = []
        for step in steps:
            run = cosimulation(name, step, coupling, stop_time)
            f = {"step": step, **figures(run)}
            out[coupling].append({**f, "J_error": abs(f["J"] - J) / J, "max_dpsi": float(
                np.abs(run["psi"] - reference["psi"]).max()) if step == H else math.nan})
    return out


def closed_loop_table(results: dict[str, dict]) -> str:
    """Part 2: each run's reference and couplings at 0.1 s."""
    return "\n".join(table(
        ["run", "model", "psi_E (rad^2)", "sum delta^2 (rad^2)", "J",
         "max abs(psi - psi_ref) (deg)"],
        ([name, model, f"{f['psi_E']:.2f}", f"{f['sum_delta2']:.3f}", f"{f['J']:.2f}",
          f"{math.degrees(f['max_dpsi']):.3f}"]
         for name, result in results.items() for model, rows in result.items()
         for f in rows if f["step"] == H), 2))


def convergence_table(results: dict[str, dict]) -> str:
    """Part 3: J at each step, its observed order and the monolithic J."""
    steps = [r["step"] for r in next(iter(results.values()))[COUPLINGS[0]]]
    return "\n".join(table(
        ["run", "coupling", *(f"J at {s:g} s" for s in steps), "order", "J monolithic"],
        ([name, coupling, *(f"{r['J']:.2f}" for r in result[coupling]),
          f"{np.median(orders([r['J_error'] for r in result[coupling]]) or [math.nan]):.2f}",
          f"{result['monolithic'][0]['J']:.2f}"]
         for name, result in results.items() for coupling in COUPLINGS), 2))


def convergence_figure(results: dict[str, dict], path: Path) -> Path:
    """|J - J_monolithic| / J_monolithic against the communication step, log-log."""
    import matplotlib.ticker
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 4.5))
    ax = fig.subplots()
    for name, result in results.items():
        for coupling, style in zip(COUPLINGS, ("o-", "s--")):
            ax.loglog([r["step"] for r in result[coupling]],
                      [max(r["J_error"], 1e-12) for r in result[coupling]], style,
                      label=f"{name}, {coupling}")
    steps = [r["step"] for r in next(iter(results.values()))[COUPLINGS[0]]]
    ax.set_xticks(steps, [f"{step:g}" for step in steps])
    ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    ax.set(xlabel="communication step (s)", ylabel="|J - J monolithic| / J monolithic",
           title="Co-simulation converges to the monolithic model")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path
