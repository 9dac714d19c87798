"""Weak disorder and the preparation scheme of Sec. VI-A on real LAMMPS (hexdem.disorder.preparation).

Small packings (4 beads per edge, 37 beads) keep the settling runs to about a second.
"""

import dataclasses
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import record
from scipy import stats
from scipy.spatial import cKDTree

from hexdem.disorder.preparation import (
    TOLERANCE_M,
    Disorder,
    Preparation,
    edge_directions,
    spaced_packing,
    walls_for_settling,
    write_stage_deck,
)
from hexdem.disorder.prestress import touching_pairs
from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.lammps.settling import SETTLED_NAME, read_data_file, read_stage
from hexdem.engines.lammps.standalone import run_deck
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.materials import PAPER_DIAMETER_M, sphere_mass
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings
from hexdem.model.triangular import hexagon

D = PAPER_DIAMETER_M
EDGE = 4


def test_diameters_follow_the_papers_normal_distribution():
    disorder = Disorder(D)
    assert disorder.sigma == 6 * TOLERANCE_M
    draws = np.concatenate([disorder.diameters_m(331, seed=3, realization=k) for k in range(100)])
    n = len(draws)
    assert abs(draws.mean() - D) < 4 * disorder.sigma / np.sqrt(n)
    assert abs(draws.std(ddof=1) - disorder.sigma) < 4 * disorder.sigma / np.sqrt(2 * n)
    assert stats.kstest(draws, stats.norm(D, disorder.sigma).cdf).pvalue > 1e-3


def test_a_realization_depends_only_on_seed_and_index():
    disorder = Disorder(D)
    first = disorder.diameters_m(331, seed=7, realization=2)
    np.testing.assert_array_equal(first, Disorder(D).diameters_m(331, seed=7, realization=2))
    others = [disorder.diameters_m(331, seed=7, realization=3), disorder.diameters_m(331, seed=8, realization=2)]
    for other in others:
        assert np.all(first != other)
        assert abs(np.corrcoef(first, other)[0, 1]) < 4 / np.sqrt(331)


def test_zero_sigma_gives_the_ideal_diameters():
    np.testing.assert_array_equal(Disorder(D, sigma_m=0.0).diameters_m(37, 0, 0), np.full(37, D))


@pytest.mark.parametrize("seed", range(5))
def test_the_spaced_lattice_has_no_overlap(seed):
    disorder = Disorder(D)
    lattice = spaced_packing(hexagon(11, D), disorder.diameters_m(331, seed, 0), disorder)
    i, j = lattice.bonds().T
    distances = np.linalg.norm(lattice.positions_m[i] - lattice.positions_m[j], axis=1)
    gaps = distances - lattice.radii_m[i] - lattice.radii_m[j]
    assert gaps.min() >= -1e-15
    assert len(touching_pairs(lattice.positions_m, lattice.diameters_m)[2]) == 0
    assert disorder.spacing_m(lattice.diameters_m) >= D + TOLERANCE_M


def test_edge_beads_are_pushed_inward_perpendicular_to_their_edge():
    lattice = hexagon(5, D)
    directions = edge_directions(lattice)
    edge = np.flatnonzero(np.linalg.norm(directions, axis=1) > 0)
    assert len(edge) == 6 * (5 - 1)
    np.testing.assert_allclose(np.linalg.norm(directions[edge], axis=1), 1.0)
    centre = lattice.positions_m.mean(axis=0)
    assert np.all(np.sum(directions[edge] * (centre - lattice.positions_m[edge]), axis=1) > 0)
    np.testing.assert_allclose(directions.sum(axis=0), 0.0, atol=1e-12)
    hole = next(w for w in lattice.walls if w.normal == (1.0, 0.0))
    for i in edge:
        walls = [w for w in lattice.walls if i in w.members or (w is hole and i == lattice.struck)]
        if len(walls) == 1:
            np.testing.assert_allclose(directions[i], walls[0].normal, atol=1e-12)


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Disorder(D, sigma_m=-1e-6), "standard deviation sigma must be >= 0"),
        (lambda: Disorder(D, tol_m=-1e-6), "tolerance tol must be >= 0"),
        (lambda: Disorder(0.0), "diameter must be > 0"),
        (lambda: Preparation(tilt_deg=90), "tilt must be below 90"),
        (lambda: Preparation(push_force_n=0.0), "push_force_n must be a positive number"),
        (lambda: Preparation(settled_rms_speed_m_s=float("nan")), "settled_rms_speed_m_s must be a positive number"),
        (lambda: Preparation(max_steps=10.5), "max_steps must be an integer"),
        (lambda: Preparation(wall_slack_m=-1e-6), "wall_slack_m must be a non-negative number"),
    ],
)
def test_bad_preparation_parameters_are_refused(make, message):
    with pytest.raises(HexdemError, match=message):
        make()


@pytest.mark.parametrize("slack", [0.0, 12.7e-6])
def test_the_settling_walls_stand_back_from_every_member_by_the_slack(slack):
    lattice = hexagon(4, D)
    walled = walls_for_settling(lattice, Preparation(wall_slack_m=slack))
    for wall in walled.walls:
        members = np.asarray(wall.members)
        np.testing.assert_allclose(
            wall.gaps_m(lattice.positions_m[members], lattice.radii_m[members]), slack, atol=1e-15
        )


# --------------------------------------------------------------------------- settling on LAMMPS


def prepare(directory, sigma_m=None, seed=0) -> SimpleNamespace:
    """Both preparation stages of a 4-per-edge hexagon, chained as the ensemble chains them."""
    disorder, preparation = Disorder(D, sigma_m=sigma_m), Preparation()
    base = build_model(RunConfig(edge_beads=EDGE, impact="striker"))
    ideal = base.packing
    spaced = spaced_packing(ideal, disorder.diameters_m(len(ideal), seed, 0), disorder)
    compact = dataclasses.replace(base, packing=spaced)
    run_deck(write_stage_deck(compact, "compact", preparation, directory / "compact"))
    compacted = read_data_file(directory / "compact" / SETTLED_NAME)
    walled = ideal.with_geometry(compacted.positions_m, compacted.diameters_m)
    settle = dataclasses.replace(base, packing=walled)
    run_deck(write_stage_deck(settle, "settle", preparation, directory / "settle"))
    settled = read_data_file(directory / "settle" / SETTLED_NAME)
    model = dataclasses.replace(base, packing=dataclasses.replace(walled, positions_m=settled.positions_m))
    return SimpleNamespace(
        directory=directory,
        preparation=preparation,
        compact=compact,
        compacted=compacted,
        settled=settled,
        model=model,
        gravity=preparation.gravity_vector_m_s2(base.impact.direction),
    )


@pytest.fixture(scope="module")
def prepared(tmp_path_factory):
    """A 4-per-edge hexagon with σ = 6 tol, compacted and settled."""
    return prepare(tmp_path_factory.mktemp("prepared"))


def hertz_overlap(model, force_n):
    """Overlap of the softest bead pair carrying ``force_n``: F = k_n sqrt(R_eff) δ^{3/2}."""
    r_eff = model.packing.radii_m.min() / 2
    return (force_n / (model.stiffness_table_pa[0, 0] * np.sqrt(r_eff))) ** (2 / 3)


def net_forces(model, gravity):
    """Net force on every bead [N] recomputed from the positions: Hertz pairs, walls, gravity."""
    lattice = model.packing
    pos, r = lattice.positions_m, lattice.radii_m
    force = np.outer(model.masses_kg[: len(lattice)], gravity)
    for i, j in cKDTree(pos).query_pairs(2 * r.max()):
        gap = pos[i] - pos[j]
        distance = np.linalg.norm(gap)
        if r[i] + r[j] > distance:
            push = (
                model.stiffness_table_pa[0, 0] * np.sqrt(r[i] * r[j] / (r[i] + r[j])) * (r[i] + r[j] - distance) ** 1.5
            )
            force[i] += push * gap / distance
            force[j] -= push * gap / distance
    for wall in model.walls:
        depth = -wall.gaps_m(pos[wall.members], r[wall.members])
        inside = depth > 0
        push = model.wall_stiffness_pa([0])[0] * np.sqrt(r[wall.members][inside]) * depth[inside] ** 1.5
        force[wall.members[inside]] += np.outer(push, wall.normal)
    return force


def test_both_stages_meet_the_settling_criterion(prepared):
    masses = sphere_mass(prepared.settled.diameters_m)
    np.testing.assert_allclose(prepared.settled.diameters_m, prepared.compact.packing.diameters_m, rtol=1e-15)
    for stage, state in (("compact", prepared.compacted), ("settle", prepared.settled)):
        result = read_stage(prepared.directory / stage)
        assert result.settled and result.steps < prepared.preparation.max_steps
        kinetic = 0.5 * np.sum(masses * np.sum(state.velocities_m_s**2, axis=1))
        assert prepared.preparation.kinetic_tolerance_j(masses) == pytest.approx(result.tolerance_j, rel=1e-12)
        assert kinetic < result.tolerance_j
    assert read_stage(prepared.directory / "settle").max_force_n < prepared.preparation.settled_max_force_n


def test_overlaps_stay_below_those_of_the_whole_applied_load(prepared):
    masses = sphere_mass(prepared.settled.diameters_m)
    pushed = np.count_nonzero(np.linalg.norm(edge_directions(prepared.compact.packing), axis=1))
    bound = hertz_overlap(prepared.model, pushed * prepared.preparation.push_force_n + masses.sum() * 9.81)
    for state in (prepared.compacted, prepared.settled):
        assert 0 < touching_pairs(state.positions_m, state.diameters_m)[2].max() < bound


def test_the_settled_packing_is_in_static_equilibrium(prepared):
    """Forces recomputed in Python from the settled positions balance, within the criterion
    (LAMMPS's fmax also holds the drag −γv of the residual velocities)."""
    force = net_forces(prepared.model, prepared.gravity)
    gamma = prepared.model.masses_kg[:-1].mean() / prepared.preparation.settle_damping_s
    drag = gamma * np.abs(prepared.settled.velocities_m_s).max()
    assert np.abs(force).max() < prepared.preparation.settled_max_force_n + drag
    weight = prepared.model.masses_kg[0] * np.linalg.norm(prepared.gravity)
    assert np.abs(force).max() < 0.01 * weight


def test_compaction_brings_equal_beads_into_a_touching_lattice(tmp_path):
    ideal = prepare(tmp_path, sigma_m=0.0)
    lattice = ideal.compact.packing
    pos = ideal.compacted.positions_m
    i, j = lattice.bonds().T
    overlaps = D - np.linalg.norm(pos[i] - pos[j], axis=1)
    pushed = np.count_nonzero(np.linalg.norm(edge_directions(lattice), axis=1))
    assert 0 < overlaps.min() and overlaps.max() < hertz_overlap(ideal.model, pushed * 5.0)


def test_gravity_acts_during_the_impact_and_the_tilted_audit_conserves_energy(prepared, tmp_path):
    """Under gravity the contact + kinetic energy changes by the work g·Σ m u; with the
    gravitational potential included the total is conserved to the integrator's accuracy
    (700 steps per contact: about 2e-6, so that the work of gravity stands out by far)."""
    config = RunConfig(edge_beads=EDGE, impact="striker", v0=0.4, duration=3e-4, steps_per_contact=700, dump_every=20)
    settings = run_settings(config, prepared.model)
    plain = record(LammpsEngine(gravity_m_s2=tuple(prepared.gravity)), prepared.model, settings, tmp_path / "impact")
    tilted = replace(plain, gravity_m_s2=tuple(prepared.gravity))
    assert tilted.energy_drift(prepared.model) < 1e-5
    energy = plain.energies_j(prepared.model)
    work = np.einsum("bk,b,k->", plain.displacements_m[-1], prepared.model.masses_kg, prepared.gravity)
    assert energy[-1] - energy[0] == pytest.approx(work, rel=0.01)
    assert plain.energy_drift(prepared.model) > 100 * tilted.energy_drift(prepared.model)
