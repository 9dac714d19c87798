"""The ternary collision approximation (Sec. IV) checked by its own physics."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hexdem.errors import HexdemError
from hexdem.theory import tca


def test_omega_solves_the_compatibility_condition():
    omega = tca.solve_omega()
    assert 2 + omega**1.5 == pytest.approx((0.5 + 1.5 * omega**1.5) / omega, rel=1e-14)
    # the sole real root: the residual changes sign only there on a fine grid of ω > 0
    grid = np.linspace(1e-3, 5.0, 20001)
    assert np.count_nonzero(np.diff(np.sign(tca.compatibility_residual(grid)))) == 1


def test_omega_makes_the_ansatz_y_equals_omega_z_an_exact_solution():
    omega = tca.solve_omega()
    state0 = [0.0, 0.0, 1.0, omega]  # y(0) = ω z(0), ẏ(0) = ω ż(0)
    sol = solve_ivp(tca.strain_rhs, (0, 1.0), state0, rtol=1e-11, atol=1e-14, dense_output=True)
    z, y = sol.sol(np.linspace(0, 1.0, 50))[:2]
    np.testing.assert_allclose(y, omega * z, atol=1e-9)


def test_reduced_equations_are_the_strains_of_the_three_bead_system():
    """Eq. (TCA_strain) with K = [[2, 1], [1/2, 3/2]] at θ = π/3, derived from the beads."""
    np.testing.assert_allclose(tca.strain_matrix(), [[2.0, 1.0], [0.5, 1.5]], atol=1e-15)
    v0 = 0.3
    full = solve_ivp(
        tca.three_bead_rhs, (0, 12.0), [0, 0, 0, v0, 0, 0], method="DOP853", rtol=1e-11, atol=1e-14, dense_output=True
    )
    reduced = solve_ivp(
        tca.strain_rhs,
        (0, 12.0),
        [0, 0, v0, v0 * np.cos(tca.THETA)],
        method="DOP853",
        rtol=1e-11,
        atol=1e-14,
        dense_output=True,
    )
    t = np.linspace(0, 12.0, 200)
    x0, x1, xa = full.sol(t)[:3]
    z, y = reduced.sol(t)[:2]
    np.testing.assert_allclose(x0 - x1, z, atol=1e-9)
    np.testing.assert_allclose(np.cos(tca.THETA) * x0 - xa, y, atol=1e-9)


@pytest.mark.parametrize("v0", [0.01, 0.1, 1.0])
def test_three_bead_energy_and_momentum_are_conserved(v0):
    event = tca.equal_velocity(v0)
    states = event.solution.sol(np.linspace(0, event.time, 400)).T
    start = states[0]
    energies = [tca.three_bead_energy(s) for s in states]
    momenta = [tca.three_bead_momentum(s) for s in states]
    np.testing.assert_allclose(energies, tca.three_bead_energy(start), rtol=1e-9)
    np.testing.assert_allclose(momenta, v0, rtol=1e-9)
    assert tca.three_bead_energy(start) == pytest.approx(0.5 * v0**2)


def test_reduced_system_conserves_its_energy():
    v = 0.2
    sol = solve_ivp(
        tca.strain_rhs, (0, 30.0), [0, 0, v, v / 2], method="DOP853", rtol=1e-11, atol=1e-14, dense_output=True
    )
    states = sol.sol(np.linspace(0, 30.0, 500)).T
    energies = np.array([tca.strain_energy(s) for s in states])
    np.testing.assert_allclose(energies, energies[0], rtol=1e-9)
    assert np.ptp(states[:, 0]) > 0.01, "the contacts were actually loaded"


def test_c_is_the_velocity_of_beads_0_and_1_when_equal_relative_to_the_bca():
    event = tca.equal_velocity(0.1)
    u0, u1, ua = event.state[3:]
    assert u0 == pytest.approx(u1, abs=1e-12)
    # momentum: 2u + 2 cos θ u_a = V0, so the side beads take exactly the missing share
    assert event.decay_factor == pytest.approx(1 - 2 * np.cos(tca.THETA) * ua / 0.1, rel=1e-9)
    assert 0 < event.decay_factor < 1


def test_c_does_not_depend_on_v0_and_t_scales_as_v_to_the_minus_one_fifth():
    events = [tca.equal_velocity(v) for v in (0.003, 0.1, 2.0)]
    np.testing.assert_allclose([e.decay_factor for e in events], events[0].decay_factor, rtol=1e-8)
    np.testing.assert_allclose([e.time * e.v0**0.2 for e in events], events[0].time * 0.003**0.2, rtol=1e-8)


def test_without_side_beads_the_tca_is_the_bca():
    """θ = π/2 decouples beads a and b: a head-on two-bead collision, c = 1 and T = τ/2."""
    from hexdem.model.hertz import contact_time

    assert tca.decay_factor(theta=np.pi / 2) == pytest.approx(1.0, abs=1e-9)
    # reduced mass 1/2, A = 1: the velocities meet at maximum compression, half the contact time
    assert tca.residence_time(0.4, theta=np.pi / 2) == pytest.approx(contact_time(0.5, 1.0, 0.4) / 2, rel=1e-8)


def test_residence_time_of_the_strain_system_matches_the_three_bead_system():
    assert tca.residence_time(0.07) == pytest.approx(tca.equal_velocity(0.07).time, rel=1e-9)


def test_hypergeometric_solution_inverts_the_ansatz_dynamics():
    """Eq. (hyperg) against z̈ = −(2 + ω^{3/2}) z^{3/2}, ż(0) = v integrated numerically."""
    omega, v = tca.solve_omega(), 0.1
    k = 2 + omega**1.5

    def rhs(t, s):
        return [s[1], -k * max(s[0], 0.0) ** 1.5]

    def turning(t, s):
        return s[1]

    turning.terminal, turning.direction = True, -1
    sol = solve_ivp(
        rhs, (0, 100.0), [0.0, v], method="DOP853", rtol=1e-12, atol=1e-15, events=turning, dense_output=True
    )
    t = np.linspace(0, sol.t_events[0][0] * 0.999, 60)
    z = sol.sol(t)[0]
    np.testing.assert_allclose(tca.hypergeometric_time(z, v, omega), t, rtol=1e-7, atol=1e-10)
    assert tca.hypergeometric_residence_time(v, omega) == pytest.approx(sol.t_events[0][0], rel=1e-8)


def test_pulse_prediction_decays_geometrically_and_slows_down():
    c = tca.decay_factor()
    prediction = tca.predict_pulses(0.1, 0, 6)
    np.testing.assert_allclose(prediction.velocity, 0.1 * c ** np.arange(7), rtol=1e-12)
    ratio = prediction.residence_time[1:] / prediction.residence_time[:-1]
    np.testing.assert_allclose(ratio, c**-0.2, rtol=1e-7)  # T ∝ V^{-1/5}
    arrival, _ = prediction.arrival_times(t_first=2.0)
    assert arrival[0] == pytest.approx(2.0 + prediction.residence_time[0])


def test_crossing_times_of_shifted_pulses():
    """Identical pulses delayed by τ per bead: speeds n, n+1 meet half-way, τ(n + 1/2) + t_peak."""
    tau, times = 0.7, np.linspace(0, 20, 4001)
    speeds = np.column_stack([np.exp(-(((times - 2.0 - tau * n) / 0.5) ** 2)) for n in range(6)])
    arrival = 2.0 + tau * np.arange(6) - 0.5 * np.sqrt(np.log(2))
    np.testing.assert_allclose(tca.crossing_times(times, speeds, arrival), 2.0 + tau * (np.arange(5) + 0.5), atol=1e-6)


def test_bad_velocity_is_a_hexdem_error():
    with pytest.raises(HexdemError, match="the TCA needs a velocity > 0, got V0 = -1.0"):
        tca.equal_velocity(-1.0)
    with pytest.raises(HexdemError, match=r"need n_last >= n_first, got 3\.\.1"):
        tca.predict_pulses(0.1, 3, 1)


def test_tca_command_prints_omega_and_c(capsys):
    import json

    from hexdem.cli.main import main

    assert main(["tca", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert tca.compatibility_residual(result["omega"]) == pytest.approx(0.0, abs=1e-12)
    assert result["c"] == pytest.approx(tca.decay_factor(), rel=1e-12)


def test_tca_figures_compare_favourably_with_the_lattice(tmp_path):
    """Fig. 5: the TCA's pulse speeds and arrival times stay within 15 % of the lattice's
    (the paper: it "favorably compares with the full numerical results")."""
    import json

    from hexdem.cli.main import main

    assert main(["tca", "--out", str(tmp_path)]) == 0
    result = json.loads((tmp_path / "tca.json").read_text())["lattice"]
    assert result["fig5a"]["beads"] == [0, 15] and result["fig5b"]["beads"][0] == 1
    for figure in ("fig5a", "fig5b"):
        assert result[figure]["max_relative_deviation_tca"] < 0.15
    for name in ("fig5a_pulse_speed", "fig5b_arrival_time"):
        assert (tmp_path / f"{name}.png").stat().st_size > 0 and (tmp_path / f"{name}.csv").stat().st_size > 0


@pytest.mark.parametrize("table", [tca.pulse_speed_table, tca.arrival_time_table])
def test_the_tca_comparison_refuses_a_run_of_several_impacts(tmp_path, table):
    """A double strike: the second front crosses the line the TCA follows (it used to be
    compared with the first impact's speed alone)."""
    from hexdem.experiments.run import simulate
    from hexdem.model.config import RunConfig

    config = RunConfig(
        edge_beads=5, engine="reference", impacts=[{"site": [0, 0]}, {"site": [0, 8], "angle_deg": 180.0}]
    )
    analysis = simulate(config, tmp_path, log=lambda message: None, trace_lines=["+30"])
    with pytest.raises(HexdemError, match="single impact; this run has 2"):
        table(analysis)
