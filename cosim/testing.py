"""A pytest plugin for your autopilot (docs/own_autopilot.md): options, fixtures, and
``check_*`` functions that raise AssertionError saying what is wrong, where and when."""
import functools
import math
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from .analysis.metrics import heading_error
from .api import overrides_of, parse_port_map, parse_setting, simulate
from .core.recording import Recording


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("cosim", "ship-autopilot co-simulation (cosim.testing)")
    group.addoption("--autopilot", type=Path, metavar="FMU",
                    help="the autopilot FMU to test (default: each scenario's own)")
    group.addoption("--map", action="append", default=[], metavar="PORT=NAME",
                    help="the FMU's name of an autopilot port, e.g. psi=heading")
    group.addoption("--set", action="append", default=[], dest="cosim_set",
                    metavar="COMPONENT.VAR=VALUE",
                    help="a parameter value for every run, e.g. autopilot.Kp=1.5")
    group.addoption("--heading-bound", type=float, default=5.0, metavar="DEG",
                    help="largest heading error allowed once a leg has settled (default 5)")
    group.addoption("--settle-time", type=float, default=60.0, metavar="S",
                    help="time a course change may take to settle (default 60)")


@pytest.fixture(scope="session")
def autopilot(request: pytest.FixtureRequest) -> Path | None:
    """The FMU given with --autopilot, or None (each scenario's own autopilot)."""
    return request.config.getoption("--autopilot")


@pytest.fixture(scope="session")
def cosim_simulate(request: pytest.FixtureRequest, autopilot) -> Callable[..., Recording]:
    """``cosim.simulate`` with the autopilot, --map and --set of the command line."""
    try:
        port_map = dict(parse_port_map(text) for text in request.config.getoption("--map"))
        pairs = [parse_setting(text) for text in request.config.getoption("cosim_set")]
        overrides_of(pairs)                 # refuses a variable given twice
    except ValueError as error:
        raise pytest.UsageError(str(error)) from None
    return functools.partial(simulate, autopilot=autopilot, port_map=port_map or None,
                             set=dict(pairs) or None)


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


def check_rudder_within_stops(run: Recording, within: float = 60.0) -> None:
    """Once a course change has settled (``within`` s), no rudder command beyond the stops."""
    delta_max = run.meta["parameters"]["ship"]["delta_max"]
    t, since = run.t, np.zeros_like(run.t)      # s since the last switch of wp_index
    for start in [0, *(np.flatnonzero(np.diff(run["guidance.wp_index"])) + 1)]:
        since[start:] = t[start:] - t[start]
    command = np.where(since >= within, np.abs(run["ship.delta_c"]), 0.0)
    k = int(np.argmax(command))
    assert command[k] <= delta_max * (1 + 1e-12), \
        f"commanded rudder {math.degrees(command[k]):.1f} deg at t = {run.t[k]:.1f} s, " \
        f"{within:g} s or more after a course change; the stops are at " \
        f"+-{math.degrees(delta_max):.1f} deg"


def check_rudder_rate(run: Recording, share: float = 0.5) -> None:
    """The rudder moves at the gear's full rate for at most ``share`` of the run (no chatter)."""
    rate_max = run.meta["parameters"]["ship"]["delta_rate_max"]
    rate = np.abs(np.diff(run["ship.delta"]) / np.diff(run.t))
    at_limit = float(np.mean(rate >= rate_max * (1 - 1e-9)))
    assert at_limit <= share, \
        f"the rudder moved at the gear's limit of {math.degrees(rate_max):.1f} deg/s for " \
        f"{100 * at_limit:.1f} % of the run (allowed {100 * share:.0f} %)"


def check_heading_settles(run: Recording, bound: float, within: float) -> None:
    """After each course change (a switch of ``guidance.wp_index``), |psi_d - psi| <= bound
    from ``within`` s on to the leg's end; shorter legs are not judged."""
    t, leg = run.t, run["guidance.wp_index"]
    error = np.abs(heading_error(run["guidance.psi_d"], run["ship.psi"]))
    starts = [0, *(np.flatnonzero(np.diff(leg)) + 1)]
    for start, end in zip(starts, [*starts[1:], len(t)]):
        settled = error[start:end][t[start:end] >= t[start] + within]
        worst = float(settled.max(initial=0.0))       # errors are >= 0; no settled step: 0
        assert worst <= bound, \
            f"heading error {math.degrees(worst):.2f} deg on the leg to waypoint " \
            f"{int(leg[start])} (from t = {t[start]:.1f} s), {within:g} s after the course " \
            f"change; allowed {math.degrees(bound):.2f} deg"
