"""LAMMPS, through hexdem's decks, against the analytic Hertz collision (hexdem.model.hertz)."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import V0, D, contact_history, record, single_bead

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.hertz import contact_time, max_overlap
from hexdem.model.materials import DELRIN, STEEL_316, hertz_stiffness, sphere_mass
from hexdem.model.walls import Wall


def test_two_sphere_collision_matches_hertz(tmp_path):
    model = GranularModel(single_bead(D), Impact(V0, striker=True), STEEL_316, wall=None)
    mass = float(sphere_mass(D, STEEL_316))
    a = hertz_stiffness(STEEL_316, STEEL_316) * np.sqrt(D / 4)
    expected_time = contact_time(mass / 2, a, V0)
    dt = 5e-8
    trajectory = record(LammpsEngine(), model, RunSettings(dt, int(1.1 * expected_time / dt), 1), tmp_path)
    start = model.initial_positions_m()
    gap = np.linalg.norm(
        (start[1] + trajectory.displacements_m[:, 1]) - (start[0] + trajectory.displacements_m[:, 0]), axis=1
    )
    duration, peak = contact_history(trajectory.times_s, D - gap)
    assert duration == pytest.approx(expected_time, rel=1e-3)
    assert peak == pytest.approx(max_overlap(mass / 2, a, V0), rel=1e-3)
    final = trajectory.velocities_m_s[-1]
    np.testing.assert_allclose(final, [[V0, 0.0], [0.0, 0.0]], atol=1e-6 * V0)


def test_sphere_on_delrin_wall_uses_the_walls_own_modulus(tmp_path):
    lattice = single_bead(D)
    wall = Wall("wall_180", (-1.0, 0.0), -D / 2, np.array([0]))
    model = GranularModel(replace(lattice, walls=(wall,)), Impact(V0), STEEL_316, wall=DELRIN)
    mass = float(sphere_mass(D, STEEL_316))
    a = hertz_stiffness(STEEL_316, DELRIN) * np.sqrt(D / 2)
    expected_time = contact_time(mass, a, V0)
    dt = 2e-7
    trajectory = record(LammpsEngine(), model, RunSettings(dt, int(1.1 * expected_time / dt), 1), tmp_path)
    depth = trajectory.displacements_m[:, 0, 0]
    duration, peak = contact_history(trajectory.times_s, depth)
    assert duration == pytest.approx(expected_time, rel=1e-3)
    assert peak == pytest.approx(max_overlap(mass, a, V0), rel=1e-3)
    np.testing.assert_allclose(trajectory.velocities_m_s[-1, 0], [-V0, 0.0], atol=1e-6 * V0)
