"""The heading observer with wave filtering (issue 40, item 4): its yaw model is our ship's,
the PD on its estimates is stable, it filters a wave-frequency heading out and follows a
turn, and in oblique waves it halves the rudder's motion; the FMU runs alike in-process and through FMI."""
from __future__ import annotations

import math

import numpy as np
import pytest

import cosim
from autopilot_fmu.design import linearised_ship
from autopilot_fmu.observer import NOMOTO_K, NOMOTO_T, HeadingObserver


def test_its_yaw_model_is_the_yaw_row_of_our_ships_sway_yaw_model():
    model = linearised_ship(0.3)
    A, b = -np.linalg.solve(model.M, model.N), np.linalg.solve(model.M, model.b)
    assert NOMOTO_T == pytest.approx(-1.0 / A[1, 1], rel=1e-12)
    assert NOMOTO_K == pytest.approx(NOMOTO_T * b[1], rel=1e-12)


def test_the_pd_on_its_estimates_is_stable_with_the_ships_sway_yaw_dynamics():
    model, observer = linearised_ship(0.3), HeadingObserver()
    A, b = -np.linalg.solve(model.M, model.N), np.linalg.solve(model.M, model.b)

    def rates(z: np.ndarray) -> np.ndarray:           # psi, v, r, then the observer's states
        delta = 2.0 * z[5] + 50.0 * z[6]              # the paper's PD on psi_hat, r_hat
        nu_dot = A @ z[1:3] + b * delta
        return np.array([z[2], *nu_dot, *observer.rates(tuple(z[3:]), z[0], delta)])
    jacobian = np.column_stack([(rates(e * 1e-7) - rates(np.zeros(8))) / 1e-7
                                for e in np.eye(8)])
    assert np.linalg.eigvals(jacobian).real.max() < -0.05


def test_it_filters_the_wave_frequency_out_and_follows_a_turn():
    observer = HeadingObserver()
    observer.start(0.3)
    psi_hat, r_hat = [], []
    for k in range(3000):                              # 300 s: 0.3 rad, waves of 0.05 rad
        t = 0.1 * k
        turn = 0.02 * max(0.0, t - 200.0)              # a turn at 0.02 rad/s from 200 s on
        observer.step(0.1, 0.3 + turn + 0.05 * math.sin(observer.omega_0 * t), 0.0)
        psi_hat.append(observer.psi_hat - 0.3 - turn)
        r_hat.append(observer.r_hat)
    assert np.ptp(psi_hat[1000:1900]) < 0.2 * 0.1       # a fifth of the waves' swing, or less
    assert np.ptp(r_hat[1000:1900]) < 0.05 * 0.05 * observer.omega_0 * 2
    assert np.mean(r_hat[-500:]) == pytest.approx(0.02, abs=0.002)  # the turn, via the bias
    saved, again = observer.snapshot(), HeadingObserver()
    again.restore(saved)
    assert again.x == observer.x
    with pytest.raises(ValueError, match="omega_c > omega_0"):
        HeadingObserver(omega_c=1.0)


def test_in_waves_it_calms_the_rudder_and_runs_alike_in_process_and_through_fmi(fmu_paths):
    runs = [cosim.simulate("waves_pd_observer", stop_time=20, backend=b)
            for b in ("inprocess", "fmi")]
    assert all(np.array_equal(runs[0][c], runs[1][c]) for c in runs[0].columns)
    filtered = cosim.simulate("waves_pd_observer", stop_time=230, backend="inprocess")
    plain = cosim.simulate("waves_pd", stop_time=230, backend="inprocess")   # true psi and r
    rate = {name: np.std(np.diff(run["ship.delta"][1100:])) for name, run in
            (("filtered", filtered), ("plain", plain))}   # the second leg: oblique seas
    assert rate["filtered"] < rate["plain"] / 1.5
