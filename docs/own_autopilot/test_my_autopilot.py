"""What every autopilot should do in the paper's scenarios: a test file to copy and extend.

    pytest docs/own_autopilot/test_my_autopilot.py --autopilot my.fmu [--map psi=heading]

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


def test_the_rudder_stays_within_its_stops(run):
    check_rudder_within_stops(run)


def test_the_rudder_moves_no_faster_than_the_steering_gear(run):
    check_rudder_rate(run)


def test_the_heading_settles_after_each_course_change(run, heading_requirement):
    check_heading_settles(run, *heading_requirement)
