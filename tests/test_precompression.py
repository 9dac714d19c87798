"""A statically precompressed packing: equilibrium bead by bead, a static run, engine agreement,
and linear sound at the speed of the equivalent triangular spring lattice."""

import numpy as np
import pytest

from hexdem.errors import HexdemError
from hexdem.experiments.compare import compare_analyses
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.model.materials import DELRIN, STEEL_316, hertz_coefficient, hertz_stiffness, sphere_mass
from hexdem.model.model_builder import build_model
from hexdem.model.precompression import (
    hole_force,
    longitudinal_sound_speed,
    precompressed_packing,
    spring_stiffness,
    static_overlap,
)
from hexdem.model.triangular import half_hexagon, hexagon

D = 0.01905
A = float(hertz_coefficient(D))
K_WALL = hertz_stiffness(STEEL_316, DELRIN)


def net_forces(lattice, f0):
    """(N, 2) net force [N] on every bead: contacts, walls, the held force on the struck bead."""
    pos = lattice.positions_m
    i, j = lattice.bonds().T
    separation = pos[j] - pos[i]
    distance = np.linalg.norm(separation, axis=1)
    force = A * np.maximum(D - distance, 0.0) ** 1.5
    net = np.zeros_like(pos)
    np.add.at(net, j, (force / distance)[:, None] * separation)
    np.add.at(net, i, -(force / distance)[:, None] * separation)
    for wall in lattice.walls:
        members = wall.members
        depth = np.maximum(-wall.gaps_m(pos[members], lattice.radii_m[members]), 0.0)
        np.add.at(
            net, members, (K_WALL * np.sqrt(lattice.radii_m[members]) * depth**1.5)[:, None] * np.asarray(wall.normal)
        )
    net[lattice.struck] += hole_force(lattice, f0)
    return force, net


@pytest.mark.parametrize("packing", [hexagon(11, D), hexagon(6, D), half_hexagon(21, 11, D)], ids=str)
@pytest.mark.parametrize("f0", [1.0, 20.0])
def test_every_contact_carries_the_target_force_in_static_equilibrium(packing, f0):
    lattice = precompressed_packing(packing, f0, A, K_WALL)
    force, net = net_forces(lattice, f0)
    np.testing.assert_allclose(force, f0, rtol=1e-8)
    assert np.max(np.abs(net)) < 1e-8 * f0
    assert hole_force(lattice, f0) == pytest.approx([np.sqrt(3) * f0, 0.0])


def test_spring_stiffness_is_the_slope_of_the_hertz_law():
    f0, delta = 5.0, static_overlap(5.0, A)
    assert A * delta**1.5 == pytest.approx(f0)
    slope = (A * (delta * (1 + 1e-6)) ** 1.5 - A * (delta * (1 - 1e-6)) ** 1.5) / (2e-6 * delta)
    assert spring_stiffness(f0, A) == pytest.approx(slope, rel=1e-8)


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_without_an_impact_the_packing_stays_static(tmp_path, engine):
    """5 N per contact, V0 = 1e-9 m/s (no impact to speak of): every bead slower than 1e-6 m/s over 1 ms."""
    analysis = simulate(RunConfig(edge_beads=6, precompression_n=5.0, v0=1e-9, duration=1e-3, engine=engine), tmp_path)
    assert np.nanmax(analysis.results.peak_speed) < 1e-6
    assert analysis.results.energy_drift < 1e-3, "round-off of the static energy is not integration error"


def test_engines_agree_on_a_precompressed_packing(tmp_path):
    config = RunConfig(edge_beads=6, precompression_n=2.0, v0=0.4, duration=5e-4)
    lammps, reference = (simulate(config.replace(engine=name), tmp_path / name) for name in ("lammps", "reference"))
    comparison = compare_analyses(lammps, reference, config.v0)
    assert comparison.n_checked > 20 and comparison.agree, comparison.verdict()


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_weak_impulses_travel_at_the_longitudinal_sound_speed(tmp_path, engine):
    """20 N per contact, V0 = 1e-4 m/s (strain v/c ~ 2e-7, far below δ0/d ~ 1e-4): the half-maximum
    front along the 0° line, fitted over beads 4 to 12 of a 16-per-edge hexagon, moves at
    c_L = sqrt(9/8) a sqrt(k/m) within 5 % (measured: +1.1 %)."""
    f0 = 20.0
    analysis = simulate(
        RunConfig(edge_beads=16, precompression_n=f0, v0=1e-4, duration=1.2e-3, engine=engine), tmp_path
    )
    r = analysis.results
    line = r.lines["0"][4:13]
    speed = np.polyfit(r.arrival_time[line], r.positions[line, 0], 1)[0]
    c_l = longitudinal_sound_speed(f0, A, float(sphere_mass(D)), D - static_overlap(f0, A))
    assert speed == pytest.approx(c_l, rel=0.05)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"precompression_n": -1.0}, "precompression_n must be a force >= 0 N"),
        ({"precompression_n": 5.0, "wall_material": "none"}, "needs walls"),
    ],
)
def test_bad_precompression_is_refused(changes, message):
    with pytest.raises(HexdemError, match=message):
        build_model(RunConfig(**changes))


def test_far_wall_is_reached_when_the_front_has_crossed_although_the_box_keeps_ringing(tmp_path):
    """20 N, V0 = 1e-3 m/s, 11 per edge: the front (c_L ≈ 500 m/s) reaches the far wall at about
    0.68 ms of the default 1.75 ms run, while reflections keep driving its corner beads to the end
    (their largest speed comes in the last samples, so they have no arrival time). Cut at 0.5 ms,
    before the front gets there, the far wall is not reached."""
    config = RunConfig(precompression_n=20.0, v0=1e-3)
    analysis = simulate(config, tmp_path / "whole")
    r, model = analysis.results, analysis.model
    far = min(model.walls, key=lambda wall: float(np.dot(wall.normal, model.impact.direction))).members
    assert np.isnan(r.arrival_time[far]).any(), "the corners are still driven at the end"
    assert np.nanmax(r.reach_time[far]) < 0.9e-3 and r.far_wall_reached  # measured: 0.81 ms at the latest
    assert not simulate(config.replace(duration=0.5e-3), tmp_path / "cut").results.far_wall_reached
