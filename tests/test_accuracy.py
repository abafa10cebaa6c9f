"""The accuracy study's reference and RK4's convergence (cosim.studies.numerical_error)."""
from __future__ import annotations

import pytest

from cosim.studies import numerical_error
from helpers import command


@pytest.fixture(scope="module")
def step_response() -> dict:
    return numerical_error.open_loop("step", t_end=60.0)


def test_rk4_converges_at_fourth_order_in_the_smooth_regime(step_response):
    """A rudder step: one kink, at the start; then RK4's error falls 16-fold per halving."""
    for signal, orders in step_response["orders"].items():
        for order in orders:
            assert 3.8 < order < 4.2, (signal, orders)


def test_rk4_keeps_fourth_order_when_the_rudder_reaches_its_command_inside_a_step():
    """A sine command moves the rudder a little every step, so the gear's kink falls
    inside almost every step; the vessel cuts its RK4 steps there (order about 2 without)."""
    sine = numerical_error.open_loop("sine", t_end=30.0)
    for signal, orders in sine["orders"].items():
        assert 3.8 < orders[0] < 4.2, (signal, orders)
    assert sine["errors"][0.1]["psi"].max < 1e-7


def test_the_reference_is_100_times_more_accurate_than_what_it_measures(step_response):
    finest = step_response["errors"][numerical_error.H_MAX[-1]]
    for signal, own in step_response["reference_error"].items():
        assert own.max * 100 <= finest[signal].max, (signal, own, finest[signal])


def test_cosimulation_converges_to_the_monolithic_model_as_the_step_shrinks():
    """calm_smc over its first turn: J's distance from the monolithic value shrinks with
    every halving of the communication step, for both couplings."""
    result = numerical_error.study("calm_smc", (0.1, 0.05, 0.025), 120.0)
    for coupling in numerical_error.COUPLINGS:
        errors = [row["J_error"] for row in result[coupling]]
        assert errors[0] > errors[1] > errors[2], errors
        assert errors[2] < 0.05


def test_the_quick_study_prints_and_writes_its_tables(tmp_path):
    from cosim import accuracy

    child = command(accuracy.main, "--quick", "--out", str(tmp_path))
    assert child.returncode == 0, child.stderr
    report = (tmp_path / "accuracy.md").read_text()
    for title in ("Integration error, open loop", "monolithic reference",
                  "J against the communication step"):
        assert title in report and title in child.stdout
    assert (tmp_path / "convergence.png").stat().st_size > 10_000
