"""The ocean current and the instruments (issue 40, items 1, 3 and 4): it carries the ship through the kinematics,
u and v stay relative to the water, no current changes no bit, and the environment FMU's
Gauss-Markov speed and direction are seeded, restorable and of the asked spread."""
from __future__ import annotations

import math

import numpy as np
import pytest

import cosim
from ship_fmu.environment import Current
from ship_fmu.sensors import Sensors
from ship_fmu.vessel import Vessel, VesselParameters


def test_a_current_carries_a_ship_at_rest_and_none_changes_no_bit():
    drifting = Vessel(VesselParameters(u0=0.0))
    for k in range(100):                                 # 10 s, shafts stopped
        drifting.step(0.1 * k, 0.1, 0.0, 0.0, 0.0, 0.0, V_c=0.1, beta_c=math.pi / 2)
    assert drifting.y == pytest.approx(1.0, rel=1e-9) and abs(drifting.x) < 1e-12
    assert drifting.u == drifting.v == drifting.r == 0.0  # still, relative to the water
    ships = [Vessel(VesselParameters(Hs=0.01, wave_seed=3)) for _ in range(2)]
    for k in range(50):
        ships[0].step(0.1 * k, 0.1, 0.2)
        ships[1].step(0.1 * k, 0.1, 0.2, V_c=0.0, beta_c=1.0)
    assert ships[0].snapshot() == ships[1].snapshot()


def test_the_current_is_seeded_restorable_and_has_the_asked_spread():
    current = Current(0.05, 1.0, T_c=20.0, sigma_V=0.01, sigma_beta=0.2, seed=4)
    samples = []
    for _ in range(20_000):
        current.step(0.5)
        samples.append((current.V, current.beta))
        if len(samples) == 100:
            saved, again = current.snapshot(), Current(0.05, 1.0, 20.0, 0.01, 0.2, 4)
            again.restore(saved)
    V, beta = np.array(samples).T
    assert V.min() >= 0.0
    assert abs(V.mean() - 0.05) < 0.002 and abs(V.std() / 0.01 - 1) < 0.1
    assert abs(beta.mean() - 1.0) < 0.04 and abs(beta.std() / 0.2 - 1) < 0.1
    again.step(0.5)
    assert (again.V, again.beta) == tuple(samples[100])       # goes on as it would have
    with pytest.raises(ValueError, match="parameter T_c must be > 0, got 0.0"):
        Current(T_c=0.0)


def test_waves_pd_current_drifts_east_and_runs_alike_in_process_and_through_fmi():
    runs = [cosim.simulate("waves_pd_current", backend=b, stop_time=60)
            for b in ("inprocess", "fmi")]
    still = cosim.simulate("waves_pd", backend="inprocess", stop_time=60)
    assert runs[0]["ship.y"][-1] > still["ship.y"][-1] + 1.0     # 0.03 m/s east for 60 s
    assert runs[0]["environment.V_c"].std() > 0.0
    np.testing.assert_array_equal(runs[0].data, runs[1].data)


def test_perfect_sensors_read_true_values_and_noisy_ones_the_asked_spread():
    perfect = Sensors()
    assert (perfect.heading(0.3), perfect.rate(-0.01), perfect.position(1.5, -2.0)) == (
        0.3, -0.01, (1.5, -2.0))
    gyro = Sensors(psi_bias=0.01, psi_noise=0.005, psi_resolution=0.001, r_noise=0.002,
                   position_noise=0.014, seed=7)
    readings = []
    for k in range(5000):
        readings.append((gyro.heading(1.0), gyro.rate(0.0), *gyro.position(3.0, 4.0)))
        if k == 10:
            again = Sensors(0.01, 0.005, 0.001, 0.0, 0.002, 0.0, 0.014, 7)
            again.restore(gyro.snapshot())
        gyro.step()
    psi_m, r_m, x_m, y_m = np.array(readings).T
    assert np.allclose(psi_m / 0.001, np.round(psi_m / 0.001), atol=1e-9)   # its steps
    assert abs(psi_m.mean() - 1.01) < 3e-4 and abs(psi_m.std() / 0.005 - 1) < 0.1
    assert abs(r_m.std() / 0.002 - 1) < 0.1 and abs(x_m.std() / 0.014 - 1) < 0.1
    assert again.heading(1.0) == readings[10][0]             # restored: the same draws
    assert Sensors(r_bias=1.0, r_resolution=5e-324).rate(0.01) == 1.01   # finer than floats
    with pytest.raises(ValueError, match="parameter r_noise must be >= 0, got -1.0"):
        Sensors(r_noise=-1.0)


def test_waves_pd_sensors_steers_by_the_measured_heading():
    runs = [cosim.simulate("waves_pd_sensors", backend=b, stop_time=30)
            for b in ("inprocess", "fmi")]
    run = runs[0]
    np.testing.assert_array_equal(run["autopilot.psi"], run["sensors.psi_m"])
    assert np.abs(run["sensors.psi_m"] - run["ship.psi"]).max() > 0.005   # bias and noise
    np.testing.assert_array_equal(runs[0].data, runs[1].data)


def test_the_wind_loads_follow_blendermann_froude_scaled_and_the_gusts_norsok():
    from ship_fmu.data import RHO_AIR, SCALE
    from ship_fmu.environment import Wind
    from ship_fmu.wind import A_L, CD_T, wind_loads
    X, Y, N = wind_loads(0.0, 0.0, 0.0, (0.0, -1.2))     # from starboard, blowing to port
    assert X == pytest.approx(0.0, abs=1e-12) and Y < 0.0 and N < 0.0   # pushed and turned
    full = 0.5 * RHO_AIR * (1.2 * math.sqrt(SCALE)) ** 2 * A_L * SCALE**2 * CD_T   # to port
    assert -Y * SCALE**3 == pytest.approx(full, rel=1e-12)
    assert wind_loads(0.3, 0.0, 0.0, (0.0, 0.0))[0] < 0.0 < wind_loads(0.0, 0.0, 0.0, (1.0, 0))[0]
    mirrored = wind_loads(0.0, 0.0, 0.0, (0.3, 1.2))     # the hull is symmetric
    assert mirrored == pytest.approx(tuple(s * c for s, c in zip(
        (1, -1, -1), wind_loads(0.0, 0.0, 0.0, (0.3, -1.2)))), rel=1e-12)
    U = 10.0                                             # m/s at full scale
    wind = Wind(U / math.sqrt(SCALE), 0.0, components=60, seed=1)
    speeds = np.array([wind.speed(t) for t in np.arange(0.0, 40_000.0, 1.0)]) * math.sqrt(SCALE)
    assert speeds.mean() == pytest.approx(U, rel=0.01)
    assert speeds.std() / speeds.mean() == pytest.approx(0.06 * (1 + 0.043 * U), rel=0.15)
    assert Wind(0.3, 1.0).speed(5.0) == 0.3 and not Wind(0.0, 0.0, 60).gusts


def test_waves_pd_wind_runs_alike_in_process_and_through_fmi(fmu_paths):
    runs = [cosim.simulate("waves_pd_wind", stop_time=20, backend=b) for b in ("inprocess", "fmi")]
    assert all(np.array_equal(runs[0][c], runs[1][c]) for c in runs[0].columns)
    still = cosim.simulate("waves_pd", stop_time=20, backend="inprocess")
    assert np.all(runs[0]["environment.V_w"] > 0.3)
    assert not np.array_equal(runs[0]["ship.y"], still["ship.y"])   # the wind pushed it
