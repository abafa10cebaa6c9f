"""What ``cosim.run`` prints for a run: eq (19) for course keeping, IMO figures for manoeuvres,
and the paper's Tables 1-2 beside ours."""
from __future__ import annotations

import math

import numpy as np

from ..core.recording import Recording
from .cost import LAMBDA, Cost, cost
from .manoeuvres import turning_circle_figures, zigzag_figures
from .metrics import sign_reversals_per_minute

PAPER_TABLES = {   # Tomera (2010), Tables 1 and 2: psi_E, delta_E, J
    "calm_pd": (128.20, 128.74, 256.94), "calm_smc": (117.07, 117.42, 234.49),
    "waves_pd": (259.38, 261.40, 520.78), "waves_smc": (194.57, 195.98, 390.55),
}


def course_keeping_report(recording: Recording, lam: float = LAMBDA, **_) -> list[str]:
    c = cost(recording, lam)
    t, delta = recording.t, recording["ship.delta"]
    stops = recording.meta.get("parameters", {}).get("ship", {}).get("delta_max", math.inf)
    pinned = np.abs(delta) >= stops * (1 - 1e-9)
    warning = ([f"warning: the rudder was at its stops for {100 * pinned.mean():.0f} % of the "
                f"run (from t = {t[pinned][0]:.0f} s): the autopilot could not hold the course"]
               if pinned.mean() > 0.1 else [])
    return warning + [f"psi_E = {c.psi_E:.2f} rad^2   sum delta^2 = {c.sum_delta2:.3f} rad^2   "
            f"lambda = {c.lam:.4f}   delta_E = {c.delta_E:.2f}   J = {c.J:.2f}",
            "(eq 19: J = psi_E + delta_E; psi_E sums the squared heading errors, delta_E = "
            "lambda sum delta^2, lambda making them equal on calm_pd; over the 0.1 s samples)",
            f"rudder: max |delta| = {math.degrees(abs(delta).max()):.1f} deg, "
            f"{sign_reversals_per_minute(t, delta):.1f} sign reversals per minute"]


def turning_circle_report(recording: Recording, **_) -> list[str]:
    tc = turning_circle_figures(*(recording[f"ship.{n}"] for n in ("x", "y", "psi", "u", "v", "r")))
    return [f"advance {tc.advance:.3f} m, transfer {tc.transfer:.3f} m, tactical diameter "
            f"{tc.tactical_diameter:.3f} m, steady yaw rate "
            f"{math.degrees(tc.steady_yaw_rate):.3f} deg/s, steady speed "
            f"{tc.steady_speed:.3f} m/s"]


def zigzag_report(recording: Recording, parameters: dict, **_) -> list[str]:
    program = parameters["program"]
    zz = zigzag_figures(recording["ship.psi"], recording["program.reversals"],
                        program["psi_switch"])
    if not zz.checked:
        psi = recording["ship.psi"]
        return [f"the turn was never checked: {zz.reversals} rudder reversal(s) of 3, heading "
                f"{math.degrees(psi[-1]):.0f} deg at t = {recording.t[-1]:.0f} s; with "
                f"{math.degrees(program['delta']):.0f} deg of counter-rudder this straight-line "
                "unstable ship keeps turning"]
    return [f"first overshoot {math.degrees(zz.first_overshoot):.2f} deg, second overshoot "
            f"{math.degrees(zz.second_overshoot):.2f} deg"]


def _label(sea: str, controller: str) -> str:
    """The paper's controllers in capitals (PD, SMC), a user's as named."""
    return controller.upper() if f"{sea}_{controller}" in PAPER_TABLES else controller


def tables(costs: dict[tuple[str, str], Cost],
           spreads: dict[tuple[str, str], str] | None = None, spreads_title: str = "") -> str:
    """Tables 1 and 2 of the paper next to ours; ``costs`` by (sea, controller).

    The sea is "calm" or "waves"; the controllers "pd" and "smc" are the paper's and
    get its values beside ours, any other (a user's autopilot) gets a row of its own.
    ``spreads``: what a perturbation ensemble says of each row (``cosim.studies.spread``),
    printed below the tables under ``spreads_title``.
    """
    lines = []
    for title, sea in (("Table 1, calm water", "calm"), ("Table 2, waves", "waves")):
        lines += [f"{title}:", f"  {'':16}{'psi_E':>9}{'delta_E':>9}{'J':>9}   |"
                  f"{'paper psi_E':>12}{'delta_E':>9}{'J':>9}"]
        for (row_sea, controller), c in costs.items():
            if row_sea != sea:
                continue
            paper = PAPER_TABLES.get(f"{sea}_{controller}")
            theirs = (f"{paper[0]:12.2f}{paper[1]:9.2f}{paper[2]:9.2f}" if paper
                      else f"{'-':>12}{'-':>9}{'-':>9}")
            name = f"{_label(sea, controller)} controller"
            lines.append(f"  {name:16}{c.psi_E:9.2f}{c.delta_E:9.2f}{c.J:9.2f}   |{theirs}")
    lam = next(iter(costs.values())).lam if costs else LAMBDA
    lines.append(f"  (lambda = {lam:.4f}, delta_E = lambda * sum delta^2; sums over the "
                 "0.1 s samples, rad^2)")
    if spreads:
        lines.append(f"{spreads_title}:")
        lines += [f"  {sea} {_label(sea, controller)}: {text}"
                  for (sea, controller), text in spreads.items()]
    return "\n".join(lines)
