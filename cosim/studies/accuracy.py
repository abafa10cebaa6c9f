"""How large are the set-up's own numerical errors? (Issue 17; part 1: integration error.)

Integration error, open loop: the ship (``ship_fmu.vessel.Vessel``, the model the
FMU wraps) under a rudder program held over each 0.1 s communication step, as a
master delivers it, integrated by its fixed-step RK4 at h_max = 0.1, 0.05 and
0.025 s, against a reference solution of the same equations: scipy's ``solve_ivp``
(DOP853, rtol = atol = 1e-12) on each communication step. The steering gear's
response is piecewise linear in time (``steering_gear.RudderMotion``); its kink,
where the rudder reaches the command or its stop, is known exactly (``reach``), and
both the reference and the vessel's RK4 restart there, so no step straddles a
discontinuity of the derivative. The reference's own error is estimated by solving again with the
tolerances halved.

Programs, 400 s from straight running at 0.3 m/s, calm water: a 20 deg rudder step;
a sine of 10 deg amplitude and 30 s period; the 20/20 zig-zag (its commands are
taken from one run and then fixed, so that every integrator sees the same input).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from fmukit.timebase import communication_point, step_count
from ship_fmu.manoeuvres import RudderProgram
from ship_fmu.steering_gear import RudderMotion, rudder_target
from ship_fmu.thrusters import actuator_model
from ship_fmu.vessel import N_PROPELLER, Vessel, VesselParameters

H = 0.1                                       # s, the communication step
H_MAX = (0.1, 0.05, 0.025)                    # s, the RK4 steps compared
SIGNALS = ("psi", "r", "x", "y")
TOLERANCE = 1e-12


def _sine(t: float) -> float:
    return math.radians(10.0) * math.sin(2.0 * math.pi * t / 30.0)


def commands(program: str, t_end: float = 400.0) -> np.ndarray:
    """The rudder command held over each communication step, rad."""
    n = step_count(0.0, t_end, H)
    times = [communication_point(0.0, k, H) for k in range(n)]
    if program == "step":
        return np.full(n, math.radians(20.0))
    if program == "sine":
        return np.array([_sine(t) for t in times])
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
    rows = [[getattr(vessel, s) for s in SIGNALS]]
    for k, command in enumerate(delta_c):
        vessel.step(communication_point(0.0, k, H), H, float(command))
        rows.append([getattr(vessel, s) for s in SIGNALS])
    return dict(zip(SIGNALS, np.array(rows).T))


def reference(delta_c: np.ndarray, tolerance: float = TOLERANCE) -> dict[str, np.ndarray]:
    """The same equations by DOP853, restarted at each communication point and at each
    kink of the steering gear's response."""
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
            y = solve_ivp(f, (a, b), y, method="DOP853", rtol=tolerance,
                          atol=tolerance).y[:, -1]
        delta = gear(H)
        rows.append([y[2], y[5], y[0], y[1]])
    return dict(zip(SIGNALS, np.array(rows).T))


@dataclass(frozen=True)
class Error:
    """Max and RMS error of one signal against the reference."""
    max: float
    rms: float


def errors(run: dict[str, np.ndarray], ref: dict[str, np.ndarray]) -> dict[str, Error]:
    out = {}
    for s in SIGNALS:
        e = np.abs(run[s] - ref[s])
        out[s] = Error(float(e.max()), float(np.sqrt(np.mean(e * e))))
    return out


def open_loop(program: str, t_end: float = 400.0) -> dict:
    """Errors of RK4 at each h_max, the observed orders, and the reference's own error."""
    delta_c = commands(program, t_end)
    ref = reference(delta_c)
    finer = reference(delta_c, TOLERANCE / 2)
    by_h = {h: errors(rk4(delta_c, h), ref) for h in H_MAX}
    orders = {s: [math.log2(by_h[a][s].max / by_h[b][s].max)
                  for a, b in zip(H_MAX, H_MAX[1:])] for s in SIGNALS}
    return {"program": program, "errors": by_h, "orders": orders,
            "reference_error": errors(finer, ref)}


# -- part 2: coupling error, closed loop --------------------------------------------------
METHOD = "LSODA"
"""Stiff where the servo slews, not elsewhere: LSODA switches between Adams and BDF as
needed, 7x faster than Radau in waves; on calm_smc both give J equal to 1e-8."""
MAX_STEP = 1.0
"""s: on a straight leg the solver's steps grow long enough to pass through a circle of
acceptance (5 m across, 16 s at 0.3 m/s) without an endpoint inside it, and the
event would be missed."""
SERVO_GAIN = 1000.0
"""1/s: the steering gear as a stiff servo in the monolithic model (see ``monolithic``)."""


def monolithic(system, stop_time: float | None = None, servo_gain: float = SERVO_GAIN,
               tolerance: float = 1e-9) -> dict[str, np.ndarray]:
    """Guidance, autopilot and ship as one ODE, the controller evaluated at every stage of
    the solver (``METHOD``), as a continuous Simulink block would be; sampled every 0.1 s
    like the master's rows.

    State: the ship's (x, y, psi, u, v, r, xi), the rudder angle delta and, for the SMC,
    its reference model (psi_z, r_z). The steering gear, a rate limiter in the FMU, is
    here delta' = clip(k (sat(delta_c) - delta), +-delta_rate_max) with k = ``servo_gain``:
    it slews at the rate limit as the FMU's does, and otherwise follows the command with a
    lag of 1/k (1 ms, against the 50 ms mean delay of a 0.1 s zero-order hold); the stiff
    k is why the solver must handle stiffness. The guidance's waypoint switching is an event (the
    circle of acceptance reached, or the leg's end passed): the solver stops there,
    switches the leg, and restarts (steps of at most ``MAX_STEP``, so that no crossing is
    stepped over). The SMC's switching term is eq (42)'s tanh boundary
    layer (phi_h), continuous: no event is needed.
    """
    from .direct import build_models, shaft_speeds

    models = build_models(system)
    guidance, autopilot, ship = (models[n] for n in ("guidance", "autopilot", "ship"))
    forces = actuator_model(ship.actuators, *shaft_speeds(system))
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


PAPER_RUNS = ("calm_pd", "calm_smc", "waves_pd", "waves_smc")
COUPLINGS = ("gauss-seidel", "jacobi")
STEPS = (0.4, 0.2, 0.1, 0.05, 0.025, 0.0125)   # s, communication steps of part 3


def cosimulation(name: str, step: float, coupling: str,
                 stop_time: float | None = None) -> dict[str, np.ndarray]:
    """Our master (the FMUs' classes in-process: the same code, without FMI's cost) at
    communication step ``step``, sampled on the 0.1 s grid; a coarser step is sampled at
    its own points, each standing for step / 0.1 samples of the grid (``weight``)."""
    import dataclasses

    from .. import scenarios
    from ..core.master import Master

    system = dataclasses.replace(scenarios.load(name), step_size=step)
    master = Master(system, coupling=coupling, backend="inprocess")
    try:
        recording = master.run(stop_time)
    finally:
        master.free()
    every = max(1, round(H / step))
    return {"t": recording.t[::every], "psi_d": recording["guidance.psi_d"][::every],
            "psi": recording["ship.psi"][::every], "delta": recording["ship.delta"][::every],
            "weight": max(1.0, step / H)}


def figures(run: dict[str, np.ndarray]) -> dict[str, float]:
    """psi_E, sum delta^2 and J of eq (19) on the 0.1 s grid."""
    from ..analysis.cost import LAMBDA
    from ..analysis.metrics import cost_terms

    psi_E, sum_delta2 = cost_terms(run["psi_d"], run["psi"], run["delta"])
    weight = run.get("weight", 1.0)
    psi_E, sum_delta2 = weight * psi_E, weight * sum_delta2
    return {"psi_E": psi_E, "sum_delta2": sum_delta2, "J": psi_E + LAMBDA * sum_delta2}


# -- the study: tables ----------------------------------------------------------------------
def open_loop_table(results: list[dict]) -> str:
    """Part 1 as a Markdown table."""
    lines = ["| program | h_max (s) | " + " | ".join(f"max / RMS error {s}" for s in SIGNALS)
             + " |", "|---|---:|" + "---:|" * len(SIGNALS)]
    for result in results:
        for h, e in result["errors"].items():
            lines.append(f"| {result['program']} | {h:g} | " + " | ".join(
                f"{e[s].max:.2e} / {e[s].rms:.2e}" for s in SIGNALS) + " |")
        lines.append(f"| {result['program']} | order | " + " | ".join(
            ", ".join(f"{o:.2f}" for o in result["orders"][s]) for s in SIGNALS) + " |")
        lines.append(f"| {result['program']} | reference, tol / 2 | " + " | ".join(
            f"{result['reference_error'][s].max:.1e}" for s in SIGNALS) + " |")
    return "\n".join(lines)


def closed_loop(name: str, stop_time: float | None = None) -> dict[str, dict]:
    """Part 2 for one run: figures of the monolithic reference and of both couplings at
    0.1 s, with the largest heading difference from the reference."""
    from .. import scenarios

    reference_run = monolithic(scenarios.load(name), stop_time)
    out = {"monolithic": {**figures(reference_run), "max_dpsi": 0.0}}
    for coupling in COUPLINGS:
        run = cosimulation(name, H, coupling, stop_time)
        out[coupling] = {**figures(run),
                         "max_dpsi": float(np.abs(run["psi"] - reference_run["psi"]).max())}
    out["_reference"] = reference_run
    return out


def closed_loop_table(results: dict[str, dict]) -> str:
    lines = ["| run | model | psi_E (rad^2) | sum delta^2 (rad^2) | J | max abs(psi - psi_ref) (deg) |",
             "|---|---|---:|---:|---:|---:|"]
    for name, result in results.items():
        for model in ("monolithic", *COUPLINGS):
            f = result[model]
            lines.append(f"| {name} | {model} | {f['psi_E']:.2f} | {f['sum_delta2']:.3f} | "
                         f"{f['J']:.2f} | {math.degrees(f['max_dpsi']):.3f} |")
    return "\n".join(lines)


def convergence(name: str, reference_figures: dict[str, float], steps=STEPS,
                stop_time: float | None = None) -> dict[str, list[dict]]:
    """Part 3 for one run: J, psi_E and sum delta^2 at each communication step, each
    coupling, and the relative distance of J from the monolithic value."""
    out = {}
    for coupling in COUPLINGS:
        rows = []
        for step in steps:
            f = figures(cosimulation(name, step, coupling, stop_time))
            f["J_error"] = abs(f["J"] - reference_figures["J"]) / reference_figures["J"]
            rows.append({"step": step, **f})
        out[coupling] = rows
    return out


def convergence_table(results: dict[str, dict], references: dict[str, dict]) -> str:
    steps = [r["step"] for r in next(iter(next(iter(results.values())).values()))]
    lines = ["| run | coupling | " + " | ".join(f"J at {s:g} s" for s in steps)
             + " | order | J monolithic |", "|---|---|" + "---:|" * (len(steps) + 2)]
    for name, by_coupling in results.items():
        for coupling, rows in by_coupling.items():
            errors = [r["J_error"] for r in rows]
            order = [math.log2(a / b) for a, b in zip(errors, errors[1:]) if a > 0 and b > 0]
            lines.append(f"| {name} | {coupling} | " + " | ".join(f"{r['J']:.2f}" for r in rows)
                         + f" | {np.median(order) if order else math.nan:.2f} | "
                           f"{references[name]['J']:.2f} |")
    return "\n".join(lines)


def convergence_figure(results: dict[str, dict], path: Path) -> Path:
    """|J - J_monolithic| / J_monolithic against the communication step, log-log."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, by_coupling in results.items():
        for coupling, rows in by_coupling.items():
            ax.loglog([r["step"] for r in rows], [max(r["J_error"], 1e-12) for r in rows],
                      "o-" if coupling == "gauss-seidel" else "s--",
                      label=f"{name}, {coupling}")
    steps = [r["step"] for r in next(iter(next(iter(results.values())).values()))]
    ax.set_xticks(steps, [f"{step:g}" for step in steps])
    ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    ax.set_xlabel("communication step (s)")
    ax.set_ylabel("|J - J monolithic| / J monolithic")
    ax.set_title("Co-simulation converges to the monolithic model")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
