"""What every autopilot should do in the paper's scenarios: a test file to copy and extend.

    pytest docs/own_autopilot/test_my_autopilot.py --autopilot my.fmu [--map psi=heading]
        [--set autopilot.Kp=1.5] [--heading-bound 5] [--settle-time 60]

Without --autopilot it tests each scenario's own autopilot (the paper's PD). The
options, the fixtures and the checks come from the ``cosim.testing`` pytest
plugin, installed with the project.
"""
import pytest

from cosim.testing import (check_finite, check_heading_settles, check_rudder_rate,
                           check_rudder_within_stops)


@pytest.fixture(scope="module", params=["calm_pd", "waves_pd"])
def run(request, cosim_simulate):
    """The paper's route in calm water and in waves, with the autopilot under test."""
    return cosim_simulate(request.param)


def test_every_signal_is_defined(run):
    check_finite(run)


def test_once_settled_it_asks_for_no_more_rudder_than_the_stops_give(run, heading_requirement):
    check_rudder_within_stops(run, within=heading_requirement[1])


def test_it_does_not_hold_the_rudder_at_the_gears_rate_limit(run):
    check_rudder_rate(run)


def test_the_heading_settles_after_each_course_change(run, heading_requirement):
    check_heading_settles(run, *heading_requirement)
