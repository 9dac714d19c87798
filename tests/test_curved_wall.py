"""A curved wall (the disc's basin) in both engines: one sphere inside a circle of radius 3r.

Head-on, the contact is Hertz's with LAMMPS's contact radius of a cylinder,
R_eff = r · 2R / (2R − r) = 1.2 r (model.packing.CurvedWall), 3.6 % shorter in time than a
plane's. Struck obliquely, the sphere slides along the curve while in contact: the engines
agree on the rebound only if both follow the circle (a tangent plane would be off by about
u_t²/R, 0.4 % of the overlap here).
"""

from dataclasses import replace

import numpy as np
import pytest
from conftest import V0, D, contact_history, record, single_bead

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.hertz import contact_time, max_overlap
from hexdem.model.materials import DELRIN, STEEL_316, hertz_stiffness, sphere_mass
from hexdem.model.walls import CurvedWall

RADIUS = 1.5 * D  # three bead radii
ENGINES = [LammpsEngine(), ReferenceEngine()]


def bead_in_a_circle(angle_deg: float) -> GranularModel:
    """A bead at the origin touching the inside of the circle at (D/2, 0), struck at ``angle_deg``."""
    wall = CurvedWall("wall_disc", (D / 2 - RADIUS, 0.0), RADIUS, np.array([0]))
    return GranularModel(replace(single_bead(D), walls=(wall,)), Impact(V0, angle_deg=angle_deg), STEEL_316, DELRIN)


def expected_contact():
    mass = float(sphere_mass(D, STEEL_316))
    r_eff = D / 2 * 2 * RADIUS / (2 * RADIUS - D / 2)
    a = hertz_stiffness(STEEL_316, DELRIN) * np.sqrt(r_eff)
    return mass, a


def test_contact_radius_is_lammps_rule():
    wall = bead_in_a_circle(0.0).packing.walls[0]
    assert wall.contact_radii_m(D / 2) == pytest.approx(1.2 * D / 2)
    np.testing.assert_allclose(wall.normals_at(np.zeros((1, 2))), [[-1.0, 0.0]])
    assert wall.gaps_m(np.zeros((1, 2)), D / 2)[0] == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_head_on_contact_time_and_overlap_are_hertz_with_the_curved_contact_radius(engine, tmp_path):
    model = bead_in_a_circle(0.0)
    mass, a = expected_contact()
    expected = contact_time(mass, a, V0)
    flat = contact_time(mass, hertz_stiffness(STEEL_316, DELRIN) * np.sqrt(D / 2), V0)
    assert expected < 0.97 * flat  # the curvature matters at this size
    dt = expected / 2000
    trajectory = record(engine, model, RunSettings(dt, int(1.1 * expected / dt), 1), tmp_path)
    duration, peak = contact_history(trajectory.times_s, trajectory.displacements_m[:, 0, 0])
    assert duration == pytest.approx(expected, rel=2e-4)
    assert peak == pytest.approx(max_overlap(mass, a, V0), rel=2e-4)
    np.testing.assert_allclose(trajectory.velocities_m_s[-1, 0], [-V0, 0.0], atol=1e-5 * V0)


def test_oblique_rebound_agrees_between_engines(tmp_path):
    model = bead_in_a_circle(40.0)
    mass, a = expected_contact()
    dt = contact_time(mass, a, V0) / 2000
    settings = RunSettings(dt, int(1.5 * contact_time(mass, a, V0) / dt), 1)
    final = {
        engine.name: record(engine, model, settings, tmp_path / engine.name).velocities_m_s[-1, 0] for engine in ENGINES
    }
    assert np.linalg.norm(final["lammps"]) == pytest.approx(V0, rel=1e-6)  # elastic: the speed comes back
    incoming = np.degrees(np.arctan2(*model.initial_velocities_m_s()[0][::-1]))
    outgoing = np.degrees(np.arctan2(*final["lammps"][::-1]))
    # The normal turns by u_t/ρ while the bead slides u_t ≈ V0 sin 40° t_c along the curve (ρ = R − r):
    # the rebound leaves a plane's mirror direction by about that angle, 0.2°.
    deflection = abs(outgoing - (180.0 - incoming))
    slide = V0 * np.sin(np.radians(40.0)) * contact_time(mass, a, V0)
    assert 0.5 < deflection / np.degrees(slide / (RADIUS - D / 2)) < 2.0
    # measured 3e-9 V0 apart; a tangent plane in either engine would leave about 2e-5 V0
    np.testing.assert_allclose(final["reference"], final["lammps"], rtol=0, atol=1e-6 * V0)
