"""The accuracy study's reference and RK4's convergence (cosim.studies.accuracy)."""
from __future__ import annotations

import pytest

from cosim.studies import accuracy


@pytest.fixture(scope="module")
def step_response() -> dict:
    return accuracy.open_loop("step", t_end=60.0)


def test_rk4_converges_at_fourth_order_in_the_smooth_regime(step_response):
    """A rudder step: one kink, at the start; then RK4's error falls 16-fold per halving."""
    for signal, orders in step_response["orders"].items():
        for order in orders:
            assert 3.8 < order < 4.2, (signal, orders)


def test_the_reference_is_100_times_more_accurate_than_what_it_measures(step_response):
    finest = step_response["errors"][accuracy.H_MAX[-1]]
    for signal, own in step_response["reference_error"].items():
        assert own.max * 100 <= finest[signal].max, (signal, own, finest[signal])
