"""The vessel's physics, called directly (no FMI)."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from cosim import simulate
from cosim.analysis.manoeuvres import turning_circle_of, zigzag_of
from ship_fmu.data import Actuators, Hull
from ship_fmu.hull import coriolis_forces, damping_forces, mass_matrix
from ship_fmu.steering_gear import RudderMotion
from ship_fmu.thrusters import actuator_model
from ship_fmu.vessel import N_PROPELLER, Vessel, VesselParameters
from fmukit.timebase import communication_point
from ship_fmu.waves import WaveComponents, WaveLoads, spectrum
from helpers import WAVE_DIGESTS, wave_digest

HULL = Hull()
DT = 0.1


def run(vessel: Vessel, seconds: float, delta_c: float = 0.0) -> Vessel:
    for k in range(round(seconds / DT)):
        vessel.step(vessel.t, DT, delta_c)
    return vessel


def random_nu(n: int, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, (n, 3)) * [1.0, 0.5, 1.0]


def test_steady_surge_speed_at_8_13_rev_per_s():
    vessel = run(Vessel(VesselParameters(u0=0.0)), 300.0)
    assert vessel.u == pytest.approx(0.300, abs=0.001)
    assert (vessel.v, vessel.r, vessel.psi) == (0.0, 0.0, 0.0)


def test_mass_matrix_matches_eq_45():
    M = mass_matrix(HULL)
    np.testing.assert_allclose(M[1:, 1:], [[33.8, 1.0948], [1.0948, 2.76]])
    assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)


def test_coriolis_does_no_work():
    for u, v, r in random_nu(2000):
        power = np.dot((u, v, r), coriolis_forces(HULL, u, v, r))
        assert abs(power) < 1e-12


def test_surge_damping_dissipates():
    for u, _, _ in random_nu(2000):
        assert u * damping_forces(HULL, u, 0.0, 0.0)[0] > 0.0


def test_damping_dissipates_at_forward_speed():
    """nu . D(nu) nu > 0 for u >= 0.2 m/s, where the ship is steered.

    The identified sway-yaw damping of Skjetne et al. (2004) is not dissipative for
    every nu: its symmetric part is indefinite (Y_r = -7.25 against Y_v = -0.89,
    N_r = -1.9), so pure sway-yaw motion with v ~ -0.7 r has nu . D nu < 0 (see the
    next test). At forward speed the surge damping outweighs that deficit.
    """
    rng = np.random.default_rng(2)
    nu = np.column_stack([rng.uniform(0.2, 1.0, 20000),
                          rng.uniform(-0.5, 0.5, 20000),
                          rng.uniform(-1.0, 1.0, 20000)])
    for u, v, r in nu:
        assert np.dot((u, v, r), damping_forces(HULL, u, v, r)) > 0.0


def test_sway_yaw_damping_is_indefinite_as_identified():
    u, v, r = 0.0, -0.05, 0.07
    assert np.dot((u, v, r), damping_forces(HULL, u, v, r)) < 0.0


def test_positive_rudder_turns_to_port():
    tau_X, tau_Y, tau_N = actuator_model(Actuators(), N_PROPELLER, N_PROPELLER, 0.0)(
        math.radians(10.0))
    assert tau_Y > 0.0 and tau_N < 0.0
    vessel = run(Vessel(), 20.0, math.radians(10.0))
    assert vessel.r < 0.0 and vessel.psi < 0.0


def test_thrust_balances_surge_damping_at_0_3_m_per_s():
    tau_X = actuator_model(Actuators(), N_PROPELLER, N_PROPELLER, 0.0)(0.0)[0]
    assert tau_X == pytest.approx(2 * 3.74e-3 * 8.13 ** 2)
    assert damping_forces(HULL, 0.2999, 0.0, 0.0)[0] == pytest.approx(tau_X, rel=1e-3)


def test_steering_gear_rate_limit_and_stops():
    rate, stop = math.radians(20.0), math.radians(35.0)
    assert RudderMotion(0.0, 1.0, stop, rate)(0.5) == pytest.approx(0.5 * rate)
    assert RudderMotion(0.0, 1.0, stop, rate)(10.0) == stop
    assert RudderMotion(0.0, -1.0, stop, rate)(10.0) == -stop
    assert RudderMotion(0.1, 0.1 + 1e-3, stop, rate)(0.5) == 0.1 + 1e-3


def test_steering_gear_kink_is_where_the_rudder_reaches_its_command_or_its_stop():
    rate, stop = math.radians(20.0), math.radians(35.0)
    gear = RudderMotion(0.1, 0.1 - 0.01, stop, rate)        # 0.01 rad back: 0.0286 s
    assert gear.reach == pytest.approx(0.01 / rate)
    assert gear(gear.reach) == gear(1.0) == 0.1 - 0.01 and gear(0.0) == 0.1
    assert gear(0.5 * gear.reach) == pytest.approx(0.095, abs=1e-15)
    assert RudderMotion(0.0, 5.0, stop, rate).reach == pytest.approx(stop / rate)
    assert RudderMotion(0.2, 0.2, stop, rate).reach == 0.0


def test_a_step_is_cut_at_the_kink():
    """The rudder reaches its command 0.03 s into a 0.1 s step: the step gives what two
    steps of 0.03 and 0.07 s give, the rudder held after the first."""
    whole, split = run(Vessel(), 5.0), run(Vessel(), 5.0)
    delta_c = 0.3 * DT * math.radians(20.0)
    whole.step(whole.t, DT, delta_c)
    t = split.t
    split.step(t, 0.3 * DT, delta_c)
    split.step(t + 0.3 * DT, 0.7 * DT, delta_c)
    for name in ("x", "y", "psi", "u", "v", "r", "delta"):
        assert getattr(whole, name) == pytest.approx(getattr(split, name), rel=1e-13,
                                                     abs=1e-16), name


def test_turning_circle_35_deg(fmu_paths):
    tc = turning_circle_of(simulate("turning_circle", backend="inprocess")).figures
    print(f"\n35 deg turning circle: advance {tc.advance:.3f} m, transfer {tc.transfer:.3f} m, "
          f"tactical diameter {tc.tactical_diameter:.3f} m ({tc.tactical_diameter / HULL.L:.2f} L), "
          f"steady yaw rate {math.degrees(tc.steady_yaw_rate):.3f} deg/s, "
          f"steady speed {tc.steady_speed:.3f} m/s")
    assert tc.advance == pytest.approx(4.4233, rel=1e-3)
    assert tc.tactical_diameter == pytest.approx(3.7017, rel=1e-3)
    assert tc.steady_yaw_rate == pytest.approx(-0.061108, rel=1e-3)
    assert 2.0 < tc.tactical_diameter / HULL.L < 5.0


def test_zigzag_20_20(fmu_paths):
    zz = zigzag_of(simulate("zigzag_20_20", backend="inprocess")).figures
    print(f"\n20/20 zig-zag: first overshoot {math.degrees(zz.overshoots[0].angle):.2f} deg, "
          f"second overshoot {math.degrees(zz.overshoots[1].angle):.2f} deg")
    assert math.degrees(zz.overshoots[0].angle) == pytest.approx(31.655, abs=0.01)
    assert math.degrees(zz.overshoots[1].angle) == pytest.approx(7.250, abs=0.01)


def test_spectrum_variance_is_hs_squared_over_16():
    Hs, T0 = 0.005, 0.8
    omega = np.linspace(0.5, 200.0, 400001)
    m0 = np.trapezoid(spectrum(omega, Hs, T0), omega)
    assert m0 == pytest.approx(Hs ** 2 / 16, rel=1e-4)
    peak = omega[np.argmax(spectrum(omega, Hs, T0))]
    assert peak == pytest.approx(2 * math.pi / T0, rel=1e-3)


def test_wave_band_holds_98_percent_of_the_variance():
    waves = WaveComponents.from_spectrum(0.005, 0.8, 50, seed=3)
    held = quad(spectrum, waves.omega.min(), waves.omega.max(), (0.005, 0.8))[0] / (
        0.005 ** 2 / 16)                                    # of m0 = Hs^2 / 16
    assert 0.9 < held <= 0.98
    assert np.sum(waves.amplitude ** 2) / 2 == pytest.approx(0.98 * 0.005 ** 2 / 16)


def test_discrete_wave_elevation_variance():
    Hs = 0.005
    waves = WaveComponents.from_spectrum(Hs, 0.8, 50, seed=4)
    t = np.arange(0.0, 3600.0, 0.05)
    eta = np.sin(np.outer(t, waves.omega) + waves.phase) @ waves.amplitude
    assert np.var(eta) == pytest.approx(Hs ** 2 / 16, rel=0.05)


def test_wave_realisation_of_a_seed_is_unchanged():
    """Frequencies, wave numbers, amplitudes and phases of seeds 0 and 7, by SHA-256:
    pinned so that no speed-up changes the sea a seed names (on every CPU:
    tests/test_cpu_variants.py)."""
    assert {seed: wave_digest(seed) for seed in WAVE_DIGESTS} == WAVE_DIGESTS


def _loads_as_written(waves: WaveLoads, t: float, xi: float, psi: float) -> tuple:
    """Eqs (14)-(16) as plainly as numpy writes them, with no work shared or kept."""
    c = waves.components
    s = c.amplitude * c.k * np.sin(c.omega * t - c.k * xi + c.phase)
    beta = waves.psi_w - psi
    force = waves._c_force * float(s.sum())
    return (force * math.cos(beta), force * math.sin(beta),
            waves._c_moment * math.sin(2.0 * beta) * float((s * s).sum()))   # not s @ s: BLAS


def test_wave_loads_at_every_rk4_stage_are_eqs_14_to_16_to_the_bit():
    """During a day at sea, each evaluation is at an RK4 stage's own time and travel, and
    gives what the equations give evaluated plainly at that stage, bit for bit: the work
    the evaluation shares between stages (omega t, the last result) changes nothing."""
    vessel = Vessel(VesselParameters(Hs=0.05, T0=1.2, psi_w=2.0, wave_seed=5))
    waves = vessel.waves
    seen = []
    vessel._wave_loads = lambda t, xi, psi: seen.append((t, xi, psi)) or waves(t, xi, psi)
    for start in (0.0, 400.0, 86_000.0):
        vessel.t = start
        for k in range(20):
            t = communication_point(start, k, DT)
            seen.clear()
            before = vessel.xi
            gear = RudderMotion(vessel.delta, 0.3 * math.sin(k))
            vessel.step(t, DT, 0.3 * math.sin(k))
            # stages 1-4 at t, t + h/2, t + h/2, t + h, of each piece of the step (cut where
            # the rudder reaches its command), and the end of the step
            cuts = (0.0, gear.reach, DT) if 0.0 < gear.reach < DT else (0.0, DT)
            stages = [t + a + f * (b - a) for a, b in zip(cuts, cuts[1:]) for f in (0, .5, .5, 1)]
            assert [s[0] for s in seen] == stages + [t + DT]
            assert seen[0][1] == before and seen[-1][1] == vessel.xi
            for stage in seen:
                assert waves(*stage) == _loads_as_written(waves, *stage)
            assert (vessel.X_w, vessel.Y_w, vessel.N_w) == _loads_as_written(waves, *seen[-1])


def _wave_run(seed: int) -> list[tuple[float, ...]]:
    vessel = Vessel(VesselParameters(Hs=0.005, wave_seed=seed))
    rows = []
    for k in range(300):
        vessel.step(k * DT, DT, 0.0)
        rows.append((vessel.x, vessel.y, vessel.psi, vessel.u, vessel.v, vessel.r,
                     vessel.X_w, vessel.Y_w, vessel.N_w))
    return rows


def test_same_seed_same_run_other_seed_other_run():
    assert _wave_run(7) == _wave_run(7)
    assert _wave_run(7) != _wave_run(8)


def test_run_does_not_depend_on_how_time_is_cut():
    """Ten 0.1 s steps and twenty 0.05 s steps agree to RK4 accuracy."""
    coarse, fine = Vessel(), Vessel()
    for k in range(100):
        coarse.step(k * 0.1, 0.1, math.radians(20.0))
    for k in range(200):
        fine.step(k * 0.05, 0.05, math.radians(20.0))
    assert fine.psi == pytest.approx(coarse.psi, abs=1e-6)
    assert fine.delta == coarse.delta


def test_encounter_phase_follows_speed_and_heading():
    """xi integrates U cos(beta): in head seas it runs against the waves."""
    vessel = run(Vessel(VesselParameters(Hs=1e-9, psi_w=math.pi)), 10.0)
    assert vessel.xi == pytest.approx(-vessel.x, rel=1e-6)


@pytest.mark.parametrize("name, value", [      # the FMU's ranges refuse the rest (test_ship_fmu)
    ("delta_max", 0.0), ("delta_rate_max", -1.0), ("delta_max", math.nan),
])
def test_invalid_parameters_are_refused_by_name(name, value):
    with pytest.raises(ValueError, match=name):
        Vessel(VesselParameters(**{name: value}))


@pytest.mark.parametrize("name", ["delta_c", "n1", "n2", "n3"])
def test_non_finite_inputs_are_refused_by_name_and_leave_the_state(name):
    vessel = Vessel()
    before = vessel.snapshot()
    inputs = {"delta_c": 0.0, "n1": 8.13, "n2": 8.13, "n3": 0.0} | {name: math.inf}
    with pytest.raises(ValueError, match=name):
        vessel.step(0.0, DT, **inputs)
    assert vessel.snapshot() == before
