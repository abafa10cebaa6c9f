"""A pytest plugin for your autopilot: options, fixtures, and checks of the exchanged signals.

Installed with the project (a ``pytest11`` entry point), so every test run in this
environment has it:

    pytest docs/own_autopilot/test_my_autopilot.py --autopilot my.fmu [--map psi=heading]

Options: ``--autopilot FMU``, ``--map PORT=NAME``, ``--heading-bound DEG`` (default 5)
and ``--settle-time S`` (default 60). Fixtures: ``autopilot`` (the FMU, or None for
the scenario's own), ``autopilot_map``, ``cosim_simulate`` (``cosim.simulate`` with
them applied) and ``heading_requirement`` (bound in rad, settle time in s). The
``check_*`` functions raise AssertionError saying what is wrong, where and when.
"""
from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from fmukit.numerics import wrap
from ship_fmu.steering_gear import DELTA_MAX, DELTA_RATE_MAX

from .api import simulate
from .core.recording import Recording


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("cosim", "ship-autopilot co-simulation (cosim.testing)")
    group.addoption("--autopilot", type=Path, metavar="FMU",
                    help="the autopilot FMU to test (default: each scenario's own)")
    group.addoption("--map", action="append", default=[], metavar="PORT=NAME",
                    help="the FMU's name of an autopilot port, e.g. psi=heading")
    group.addoption("--heading-bound", type=float, default=5.0, metavar="DEG",
                    help="largest heading error allowed once a leg has settled (default 5)")
    group.addoption("--settle-time", type=float, default=60.0, metavar="S",
                    help="time a course change may take to settle (default 60)")


@pytest.fixture(scope="session")
def autopilot(request: pytest.FixtureRequest) -> Path | None:
    """The FMU given with --autopilot, or None (each scenario's own autopilot)."""
    return request.config.getoption("--autopilot")


@pytest.fixture(scope="session")
def autopilot_map(request: pytest.FixtureRequest) -> dict[str, str]:
    """The --map options as {port: the FMU's name}."""
    pairs = [text.partition("=") for text in request.config.getoption("--map")]
    bad = [port for port, sep, name in pairs if not (sep and port and name)]
    if bad:
        raise pytest.UsageError(f"--map expects PORT=NAME, e.g. psi=heading; got {bad}")
    return {port: name for port, _, name in pairs}


@pytest.fixture(scope="session")
def cosim_simulate(autopilot, autopilot_map) -> Callable[..., Recording]:
    """``cosim.simulate`` with the autopilot of the command line in every scenario."""
    return functools.partial(simulate, autopilot=autopilot, port_map=autopilot_map or None)


@pytest.fixture(scope="session")
def heading_requirement(request: pytest.FixtureRequest) -> tuple[float, float]:
    """(largest settled heading error in rad, settle time in s), from the options."""
    return (math.radians(request.config.getoption("--heading-bound")),
            request.config.getoption("--settle-time"))


def check_finite(run: Recording) -> None:
    """Every signal is a number at every step."""
    bad = [c for c in run.columns if not np.all(np.isfinite(run[c]))]
    assert not bad, f"not finite: {', '.join(bad)} (first at t = " \
                    f"{run.t[np.argmax(~np.isfinite(run[bad[0]]))]:.1f} s)"


def check_rudder_within_stops(run: Recording, delta_max: float = DELTA_MAX) -> None:
    """The rudder (``ship.delta``) never passes its stops."""
    delta = np.abs(run["ship.delta"])
    k = int(np.argmax(delta))
    assert delta[k] <= delta_max * (1 + 1e-12), \
        f"rudder at {math.degrees(delta[k]):.2f} deg at t = {run.t[k]:.1f} s, beyond the " \
        f"stops at {math.degrees(delta_max):.1f} deg"


def check_rudder_rate(run: Recording, delta_rate_max: float = DELTA_RATE_MAX) -> None:
    """The rudder moves no faster than the steering gear can move it."""
    rate = np.abs(np.diff(run["ship.delta"]) / np.diff(run.t))
    k = int(np.argmax(rate))
    assert rate[k] <= delta_rate_max * (1 + 1e-9), \
        f"rudder moving at {math.degrees(rate[k]):.2f} deg/s at t = {run.t[k]:.1f} s, faster " \
        f"than the gear's {math.degrees(delta_rate_max):.1f} deg/s"


def check_heading_settles(run: Recording, bound: float, within: float) -> None:
    """After each course change, |psi_d - psi| <= bound from ``within`` s on, to the leg's end.

    A leg is the time between two switches of ``guidance.wp_index``; legs shorter
    than ``within`` are not judged.
    """
    t, leg = run.t, run["guidance.wp_index"]
    error = np.abs([wrap(d - p) for d, p in zip(run["guidance.psi_d"], run["ship.psi"])])
    starts = [0, *(np.flatnonzero(np.diff(leg)) + 1)]
    for start, end in zip(starts, [*starts[1:], len(t)]):
        settled = (t[start:end] >= t[start] + within)
        if not settled.any():
            continue
        worst = float(error[start:end][settled].max())
        assert worst <= bound, \
            f"heading error {math.degrees(worst):.2f} deg on the leg to waypoint " \
            f"{int(leg[start])} (from t = {t[start]:.1f} s), {within:g} s after the course " \
            f"change; allowed {math.degrees(bound):.2f} deg"
