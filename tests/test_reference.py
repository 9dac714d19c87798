"""The reference integrator (hexdem.engines.reference.engine) against physics: Hertz law, energy, symmetry, scaling."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import V0, D, contact_history, disordered_model, record, settings_of, single_bead

from hexdem.analysis.energy import contact_energy_j
from hexdem.engines.reference.engine import PARAMETERS_NAME, ReferenceEngine, ReferenceSystem
from hexdem.errors import HexdemError
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.hertz import contact_time, max_overlap
from hexdem.model.materials import DELRIN, STEEL_316, hertz_stiffness, sphere_mass
from hexdem.model.model_builder import build_model
from hexdem.model.units import SI, nondimensional
from hexdem.model.walls import Wall

#: A small experiment: 5 beads per edge (61 beads), everything else the paper's defaults.
SMALL = RunConfig(edge_beads=5, engine="reference")


@pytest.mark.parametrize("units", [SI, nondimensional(D)], ids=["si", "nondimensional"])
def test_forces_are_minus_the_gradient_of_the_hertz_energy(units):
    """Bonds with per-pair contact distance and R_eff, the striker bond and the walls, checked
    against hexdem.analysis.energy (all overlapping pairs, V = (2/5) k_n sqrt(R_eff) δ^{5/2})."""
    model = disordered_model()
    start = model.initial_positions_m()
    q = np.random.default_rng(2).normal(scale=3e-4, size=start.shape)
    step = 1e-9
    gradient = np.zeros_like(q)
    for body in range(model.n_bodies):
        for axis in range(2):
            shift = np.zeros_like(q)
            shift[body, axis] = step
            gradient[body, axis] = (
                contact_energy_j(start + q + shift, model) - contact_energy_j(start + q - shift, model)
            ) / (2 * step)
    assert np.count_nonzero(gradient) > model.n_bodies  # the perturbation makes many contacts
    force = ReferenceSystem.from_model(model, units).forces(q / units.length_m) * units.force_n
    np.testing.assert_allclose(force, -gradient, rtol=1e-6, atol=1e-6 * np.abs(gradient).max())


def run_until(model, duration_s, tmp_path, steps=4000):
    """A reference run sampled at every step of ``duration_s / steps``."""
    return record(ReferenceEngine(), model, RunSettings(duration_s / steps, steps, 1), tmp_path)


@pytest.mark.parametrize("ratio", [1.0, 0.6], ids=["equal", "smaller-struck-bead"])
def test_two_bead_collision_matches_analytic_hertz(tmp_path, ratio):
    lattice = replace(single_bead(D), diameters_m=np.array([ratio * D]))
    model = GranularModel(lattice, Impact(V0, striker=True), STEEL_316, wall=None)
    striker_mass, bead_mass = model.masses_kg[1], model.masses_kg[0]
    mu = striker_mass * bead_mass / (striker_mass + bead_mass)
    a = hertz_stiffness(STEEL_316, STEEL_316) * np.sqrt(D / 2 * ratio * D / 2 / (D / 2 + ratio * D / 2))
    expected = contact_time(mu, a, V0)
    trajectory = run_until(model, 1.1 * expected, tmp_path)
    centres = model.initial_positions_m() + trajectory.displacements_m
    overlap = (1 + ratio) * D / 2 - np.linalg.norm(centres[:, 0] - centres[:, 1], axis=1)
    duration, peak = contact_history(trajectory.times_s, overlap)
    assert duration == pytest.approx(expected, rel=1e-4)
    assert peak == pytest.approx(max_overlap(mu, a, V0), rel=1e-5)
    total = striker_mass + bead_mass  # elastic head-on collision: momentum and energy conserved
    expected_final = [[2 * striker_mass / total * V0, 0.0], [(striker_mass - bead_mass) / total * V0, 0.0]]
    np.testing.assert_allclose(trajectory.velocities_m_s[-1], expected_final, atol=1e-7 * V0)


def test_sphere_on_a_delrin_wall_uses_the_walls_own_modulus(tmp_path):
    wall = Wall("wall_180", (-1.0, 0.0), -D / 2, np.array([0]))
    model = GranularModel(replace(single_bead(D), walls=(wall,)), Impact(V0), STEEL_316, wall=DELRIN)
    mass = float(sphere_mass(D, STEEL_316))
    a = hertz_stiffness(STEEL_316, DELRIN) * np.sqrt(D / 2)
    expected = contact_time(mass, a, V0)
    trajectory = run_until(model, 1.1 * expected, tmp_path)
    duration, peak = contact_history(trajectory.times_s, trajectory.displacements_m[:, 0, 0])
    assert duration == pytest.approx(expected, rel=1e-4)
    assert peak == pytest.approx(max_overlap(mass, a, V0), rel=1e-5)
    np.testing.assert_allclose(trajectory.velocities_m_s[-1, 0], [-V0, 0.0], atol=1e-7 * V0)


@pytest.mark.parametrize(
    "changes", [{}, {"impact": "striker", "strike_angle_deg": 30.0}], ids=["velocity-0deg", "striker-30deg"]
)
def test_energy_is_conserved(tmp_path, changes):
    """RK4 at the default 140 steps per contact: about 3e-7 (bench_accuracy.py), against Verlet's 4.5e-5."""
    analysis = simulate(SMALL.replace(**changes), tmp_path)
    assert analysis.results.far_wall_reached  # the wave has hit the walls: every contact kind acted
    assert analysis.results.energy_drift < 1e-6


def line_peaks(analysis, line):
    r = analysis.results
    return r.peak_speed[r.lines[line]], r.arrival_time[r.lines[line]]


def test_halving_the_time_step_changes_peaks_by_less_than_1e_4(tmp_path):
    config = SMALL.replace(strike_angle_deg=30.0)
    dt = settings_of(config).dt_s
    coarse = simulate(config, tmp_path / "dt")
    fine = simulate(config.replace(dt=dt / 2, dump_every=2 * settings_of(config).dump_every), tmp_path / "dt2")
    for line in ("0", "+30", "-30"):
        (p1, t1), (p2, t2) = line_peaks(coarse, line), line_peaks(fine, line)
        moving = p1 > 0.01 * config.v0
        np.testing.assert_allclose(p2[moving], p1[moving], rtol=1e-4)
        np.testing.assert_allclose(t2[moving], t1[moving], rtol=0, atol=1e-3 * dt)


def test_plus_and_minus_30_degree_strikes_are_mirror_images(tmp_path):
    plus = simulate(SMALL.replace(strike_angle_deg=30.0), tmp_path / "plus")
    minus = simulate(SMALL.replace(strike_angle_deg=-30.0), tmp_path / "minus")
    for a, b in (("+30", "-30"), ("-30", "+30"), ("0", "0")):
        (p1, t1), (p2, t2) = line_peaks(plus, a), line_peaks(minus, b)
        np.testing.assert_allclose(p2, p1, rtol=1e-9)
        np.testing.assert_allclose(t2, t1, rtol=1e-9)
    assert line_peaks(plus, "+30")[0][5] > 2 * line_peaks(plus, "-30")[0][5]  # the strike's line carries the wave


def test_nondimensional_run_is_the_scaled_si_run(tmp_path):
    """Eq. (scaling): in A = d = M = 1 the same impact gives the same V_n/V0 and scaled times."""
    si = SMALL.replace(strike_angle_deg=30.0)
    scale = nondimensional(D)
    settings = settings_of(si)
    nd = si.replace(
        units="nondimensional",
        v0=si.v0 / scale.velocity_m_s,
        dt=settings.dt_s / scale.time_s,
        duration=settings.duration_s / scale.time_s,
    )
    a, b = simulate(si, tmp_path / "si"), simulate(nd, tmp_path / "nd")
    assert b.engine["units"] == "nondimensional"
    np.testing.assert_allclose(b.results.peak_speed / nd.v0, a.results.peak_speed / si.v0, rtol=1e-9)
    np.testing.assert_allclose(b.results.arrival_time * scale.time_s, a.results.arrival_time, rtol=1e-9)


def test_samples_start_at_zero_every_dump_interval_and_the_run_is_described(tmp_path):
    model = build_model(SMALL)
    trajectory = record(ReferenceEngine(), model, RunSettings(1e-7, 105, 10), tmp_path / "deck")
    np.testing.assert_allclose(trajectory.times_s, np.arange(11) * 1e-6)
    assert trajectory.velocities_m_s.shape == (11, model.n_bodies, 2)
    np.testing.assert_array_equal(trajectory.velocities_m_s[0], model.initial_velocities_m_s())
    assert (tmp_path / "deck" / PARAMETERS_NAME).stat().st_size > 0
    assert trajectory.engine["n_pairs"] == len(model.packing.bonds())  # a triangular packing's list: its touching pairs


@pytest.mark.parametrize(
    "settings, message",
    [
        (RunSettings(0.0, 10, 1), "time step"),
        (RunSettings(float("nan"), 10, 1), "time step"),
        (RunSettings(1e-7, 0, 1), "n_steps"),
        (RunSettings(1e-7, 10, 0), "dump_every"),
    ],
)
def test_bad_settings_are_one_line_errors(tmp_path, settings, message):
    with pytest.raises(HexdemError, match=message):
        ReferenceEngine().run(build_model(SMALL), settings, tmp_path, lambda sample: None)


def test_divergence_is_reported(tmp_path):
    """A step so long that the striker lands on the struck bead's centre (r = 0) must not pass silently."""
    d, v0 = 2.0**-6, 0.5
    model = GranularModel(single_bead(d), Impact(v0, striker=True), STEEL_316, wall=None)
    with pytest.raises(HexdemError, match="diverged"):
        record(ReferenceEngine(), model, RunSettings(2 * d / v0, 3, 1), tmp_path)
