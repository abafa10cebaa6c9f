"""The MSC.137(76) 5.3 criteria of a standard manoeuvre, for ships of 100 m and over: on
this 1:70 model through Froude scaling (ship lengths the same, L/V times sqrt(70))."""
from __future__ import annotations

import math
from dataclasses import dataclass

from ship_fmu.data import Hull

from ..core.recording import Recording
from .manoeuvres import (TURNING_RUDDER, TurningCircle, ZigZagResult, turning_circle_figures,
                         zigzag_figures)
from .seastate import SCALE

STANDARD = "MSC.137(76)"
ADVANCE_LIMIT = 4.5                   # ship lengths, 5.3.1
TACTICAL_DIAMETER_LIMIT = 5.0         # ship lengths, 5.3.1
INITIAL_TURNING_LIMIT = 2.5           # ship lengths, 5.3.2
FIRST_OVERSHOOT_20_LIMIT = math.radians(25.0)   # 5.3.3.3
_SAME_ANGLE = 1e-6                    # rad: a test's angles match the standard's within this


@dataclass(frozen=True)
class Criterion:
    """One MSC.137(76) criterion: a figure of the run, its limit and the clause setting it."""
    figure: str      # what is judged, in the standard's words
    value: float     # in ``unit``; NaN if the run never produced it (a turn never checked)
    limit: float     # the largest value that passes, in ``unit``
    unit: str        # "L" (ship lengths) or "rad"
    clause: str      # of MSC.137(76)
    basis: str = ""  # what set the limit, if it depends on the ship (L/V)
    missing: str = "not reached in the run"   # why ``value`` is NaN, when it is
    at_least: bool = False   # ``value`` is a lower bound: the run ended before the figure

    @property
    def verdict(self) -> str:
        """PASS, FAIL, or OPEN: a figure not reached, or only a lower bound within the limit."""
        if self.value > self.limit:
            return "FAIL"
        return "OPEN" if self.at_least or math.isnan(self.value) else "PASS"


def length_over_speed(length: float, speed: float, scale: float = SCALE) -> float:
    """L/V at full scale, s, of a model of ``length`` m at ``speed`` m/s (Froude)."""
    return math.sqrt(scale) * length / speed


def overshoot_limits(lv: float) -> tuple[float, float]:
    """(first, second) 10/10 overshoot limits, rad, for L/V in s at full scale (5.3.3.1-2)."""
    lv = min(max(lv, 10.0), 30.0)          # 10 and 25 deg below 10 s, 20 and 40 above 30 s
    return math.radians(5.0 + 0.5 * lv), math.radians(17.5 + 0.75 * lv)


def _is(angle: float, degrees: float) -> bool:
    return abs(angle - math.radians(degrees)) < _SAME_ANGLE


def turning_circle_criteria(tc: TurningCircle, delta: float,
                            delta_max: float) -> tuple[Criterion, ...]:
    """MSC.137(76) 5.3.1, at 35 deg rudder or the gear's largest; none for another angle."""
    if abs(delta - min(TURNING_RUDDER, delta_max)) >= _SAME_ANGLE:
        return ()
    return (Criterion("advance", tc.advance / Hull.L, ADVANCE_LIMIT, "L", "5.3.1",
                      missing="none: the heading never changed by 90 deg"),
            Criterion("tactical diameter", tc.tactical_diameter / Hull.L,
                      TACTICAL_DIAMETER_LIMIT, "L", "5.3.1",
                      missing="none: the heading never changed by 180 deg"))


def zigzag_criteria(zz: ZigZagResult, delta: float, approach_speed: float
                    ) -> tuple[Criterion, ...]:
    """MSC.137(76) 5.3.2-3 for a 10/10 or a 20/20 zig-zag; none for another test."""
    if _is(delta, 10.0) and _is(zz.psi_switch, 10.0):
        lv = length_over_speed(Hull.L, approach_speed)
        first, second = overshoot_limits(lv)
        basis = (f"L/V = {lv:.1f} s at full scale (1:{SCALE:g}; "
                 f"{Hull.L / approach_speed:.2f} s for the model)")
        return (Criterion("initial turning: distance by 10 deg heading change",
                          zz.initial_turning_distance / Hull.L, INITIAL_TURNING_LIMIT, "L",
                          "5.3.2", missing="none: the heading never changed by 10 deg"),
                _overshoot_criterion(zz, 1, first, "5.3.3.1", basis),
                _overshoot_criterion(zz, 2, second, "5.3.3.2", basis))
    if _is(delta, 20.0) and _is(zz.psi_switch, 20.0):
        return (_overshoot_criterion(zz, 1, FIRST_OVERSHOOT_20_LIMIT, "5.3.3.3"),)
    return ()


def _overshoot_criterion(zz: ZigZagResult, n: int, limit: float, clause: str,
                         basis: str = "") -> Criterion:
    value, at_least = zz.overshoot_bound(n)
    return Criterion(f"{('first', 'second')[n - 1]} overshoot", value, limit, "rad", clause,
                     basis, "none: the run ended before that turn", at_least)


@dataclass(frozen=True)
class Assessment:
    """A recorded manoeuvre: its figures and the criteria that apply to it."""
    figures: TurningCircle | ZigZagResult
    criteria: tuple[Criterion, ...]
    delta: float                # rad, the test's rudder angle


def turning_circle_of(run: Recording) -> Assessment:
    tc = turning_circle_figures(*(run[f"ship.{n}"] for n in ("x", "y", "psi", "u", "v", "r")))
    p, delta = run.meta["parameters"], run.meta["parameters"]["program"]["delta"]
    return Assessment(tc, turning_circle_criteria(tc, delta, p["ship"]["delta_max"]), delta)


def zigzag_of(run: Recording) -> Assessment:
    program = run.meta["parameters"]["program"]
    zz = zigzag_figures(run["ship.psi"], run["program.reversals"], program["psi_switch"],
                        run.t, run["ship.x"], run["ship.y"])
    approach = math.hypot(run["ship.u"][0], run["ship.v"][0])
    return Assessment(zz, zigzag_criteria(zz, program["delta"], approach), program["delta"])
