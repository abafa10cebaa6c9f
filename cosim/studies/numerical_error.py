"""The accuracy study (docs/reproduction.md). Part 1: the ship (``Vessel``) under a rudder program
held over each 0.1 s step, by its RK4 at several h_max, against DOP853 restarted at each kink of
the steering gear. Parts 2-3: the paper's runs by our master, Gauss-Seidel and Jacobi, against a
monolithic reference with the controller inside the solver, by eq (19), over communication steps."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_ivp

from fmukit.timebase import communication_point, step_count
from ship_fmu.manoeuvres import RudderProgram
from ship_fmu.steering_gear import RudderMotion, rudder_target
from ship_fmu.thrusters import actuator_model
from ship_fmu.vessel import N_PROPELLER, Vessel, VesselParameters

from .. import scenarios
from ..analysis.metrics import LAMBDA, cost_terms
from ..core.master import Master
from ..ensemble.reference import COMPONENTS, initialise
from . import table

H = 0.1                                       # s, the communication step
H_MAX = (0.1, 0.05, 0.025)                    # s, the RK4 steps compared
STATES = ("psi", "r", "x", "y")
TOLERANCE = 1e-12                             # of part 1's reference
PAPER_RUNS = ("calm_pd", "calm_smc", "waves_pd", "waves_smc")
COUPLINGS = ("gauss-seidel", "jacobi")
STEPS = (0.4, 0.2, 0.1, 0.05, 0.025, 0.0125)   # s, communication steps of part 3
METHOD = "LSODA"        # stiff where the servo slews, not elsewhere: Adams and BDF in turn
MAX_STEP = 1.0          # s: a longer step could pass a circle of acceptance unseen
SERVO_GAIN = 1000.0     # 1/s: the steering gear as a stiff servo
MONOLITHIC_TOLERANCE = 1e-9


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
        solution = solve_ivp(rhs, (t, stop), Y, method=METHOD, rtol=MONOLITHIC_TOLERANCE,
                             atol=MONOLITHIC_TOLERANCE, dense_output=True, events=events,
                             args=(leg,), max_step=MAX_STEP)
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
    """Our master at ``step`` on the 0.1 s grid (a coarser step: its points, each weighed)."""
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
