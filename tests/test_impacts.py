"""Several impacts, flat strikers and extra observation lines: budgets, symmetry, and bad input."""

import json

import numpy as np
import pytest
from conftest import read_csv, record

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.errors import HexdemError
from hexdem.experiments.run import run_experiment, simulate
from hexdem.model.config import RunConfig
from hexdem.model.materials import BRASS, STEEL_316
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.run_settings import run_settings

ENGINES = [LammpsEngine(), ReferenceEngine()]
#: A free hexagon of 5 per edge (sites n = 0..8; {0, 8} is the middle of the right edge, {8, 4}
#: the top of the middle column) struck by three strikers: steel from the left at 0.4 m/s, brass
#: from the right at 0.3 m/s, steel from above at 0.4 m/s.
THREE_STRIKERS = RunConfig(
    edge_beads=5,
    wall_material="none",
    impact="striker",
    duration=4e-4,
    impacts=[
        {"site": [0, 0]},
        {"site": [0, 8], "angle_deg": 180.0, "striker_material": "brass", "v0": 0.3},
        {"site": [8, 4], "angle_deg": -90.0},
    ],
)


def sphere_mass(material, d=0.01905):
    return material.density_kg_m3 * np.pi * d**3 / 6


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
def test_three_strikers_keep_the_momentum_and_energy_they_bring(engine, tmp_path):
    """No walls and no external force: Σ m v stays the strikers' initial momentum, worked out by
    hand, and the energy their kinetic energy, to the integrator's dt² error."""
    model = build_model(THREE_STRIKERS)
    assert model.n_bodies == 61 + 3 and len(model.strikers) == 3
    steel, brass = sphere_mass(STEEL_316), sphere_mass(BRASS)
    momentum = np.array([steel * 0.4 - brass * 0.3, -steel * 0.4])
    energy = 0.5 * steel * 0.4**2 * 2 + 0.5 * brass * 0.3**2
    trajectory = record(engine, model, run_settings(THREE_STRIKERS, model), tmp_path)
    p = np.einsum("b,fbk->fk", model.masses_kg, trajectory.velocities_m_s)
    np.testing.assert_allclose(p, np.tile(momentum, (len(p), 1)), rtol=0, atol=1e-12 * np.abs(momentum).max())
    energies = trajectory.energies_j(model)
    assert energies[0] == pytest.approx(energy, rel=1e-14)
    assert np.max(np.abs(energies / energy - 1)) < 1e-4  # velocity Verlet at 140 steps per contact: ~4e-5
    moved = trajectory.speeds_m_s[-1, :61] > 1e-3 * 0.3
    assert moved.sum() > 40  # the waves went through the packing


def mirror(lattice, site_map):
    """Index of each bead's mirror image under ``site_map`` (m, n) → (m', n')."""
    return np.array([lattice.index_of(*site_map(m, n)) for m, n in lattice.labels.tolist()])


@pytest.mark.parametrize("engine", ["lammps", "reference"])
@pytest.mark.parametrize("case", ["double-velocity", "double-striker", "flat-striker"])
def test_a_symmetric_strike_gives_mirror_symmetric_pulses(engine, case, tmp_path):
    """Two equal strikes on opposite edges of a hexagon (x → L − x: {m, n} → {m, 8 − n}), and a
    flat striker on the left edge (y → −y: {m, n} → {−m, n}): mirror beads have equal peaks
    and arrival times."""
    double = [{"site": [0, 0]}, {"site": [0, 8], "angle_deg": 180.0}]
    changes = {
        "double-velocity": {"impacts": double},
        "double-striker": {"impacts": double, "impact": "striker"},
        "flat-striker": {"impacts": [{"edge_deg": 0.0}], "impact": "striker"},
    }[case]
    config = RunConfig(edge_beads=5, engine=engine, **changes)
    analysis = simulate(config, tmp_path)
    r, lattice = analysis.results, analysis.model.packing
    image = mirror(lattice, (lambda m, n: (-m, n)) if case == "flat-striker" else (lambda m, n: (m, 8 - n)))
    assert np.all(image >= 0)
    np.testing.assert_allclose(r.peak_speed[image], r.peak_speed, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(r.arrival_time[image], r.arrival_time, rtol=0, atol=1e-10)
    assert np.sum(r.peak_speed > 0.01 * config.v0) > len(lattice) / 2  # the waves crossed the packing


def test_a_flat_striker_is_one_sphere_per_edge_bead_and_replaces_the_wall():
    model = build_model(RunConfig(impact="striker", impacts=[{"edge_deg": 0.0}]))
    left = np.flatnonzero(model.packing.labels[:, 1] == 0)
    assert sorted(model.struck_beads) == sorted(left) and len(left) == 11
    assert len(model.strikers) == 11 and "wall_000" not in [w.name for w in model.walls]
    velocities = model.initial_velocities_m_s()[len(model.packing) :]
    np.testing.assert_array_equal(velocities, np.tile([0.4, 0.0], (11, 1)))
    gaps = np.diff(model.initial_positions_m()[len(model.packing) :, 1])
    np.testing.assert_allclose(np.sort(np.abs(gaps)), 0.01905, rtol=1e-12)  # the spheres touch: a plate


def test_every_struck_bead_sits_in_a_hole_of_the_wall_it_is_pushed_through():
    model = build_model(
        RunConfig(
            edge_beads=5,
            impacts=[{"site": [0, 0]}, {"site": [0, 8], "angle_deg": 180.0}, {"site": [-4, 0], "angle_deg": 0.0}],
        )
    )
    members = {w.name: {tuple(model.packing.labels[b]) for b in w.members} for w in model.walls}
    assert (0, 0) not in members["wall_000"] and (0, 8) not in members["wall_180"]
    assert (-4, 0) not in members["wall_000"] and (-4, 0) in members["wall_060"]  # the corner's other wall stays


def test_holes_do_not_depend_on_the_order_of_the_impacts_and_only_struck_beads_sit_in_one():
    first = build_model(RunConfig(edge_beads=4, impacts=[{"site": [0, 0]}, {"site": [2, 6], "angle_deg": -120.0}]))
    second = build_model(RunConfig(edge_beads=4, impacts=[{"site": [2, 6], "angle_deg": -120.0}, {"site": [0, 0]}]))
    assert {w.name: w.members.tolist() for w in first.walls} == {w.name: w.members.tolist() for w in second.walls}
    far = build_model(RunConfig(edge_beads=4, impacts=[{"edge_deg": 180.0}]))  # {0, 0} is not struck: no hole there
    assert far.packing.struck in next(w for w in far.walls if w.name == "wall_000").members


def test_the_papers_single_impact_keeps_its_one_hole_in_the_struck_edges_wall():
    """In a hexagon of 2 per edge {0, 0} is also the corner of the lower-left edge: it stays on that wall."""
    walls = {w.name: w.members for w in build_packing(RunConfig(edge_beads=2)).walls}
    struck = build_packing(RunConfig(edge_beads=2)).struck
    assert struck not in walls["wall_000"] and struck in walls["wall_060"]


def test_a_deck_beyond_lammpss_32_groups_is_refused_before_it_runs(tmp_path):
    from hexdem.engines.lammps.deck import render_input

    interior = [[m, n] for n in range(2, 8) for m in range(-4, 5) if (m + n) % 2 == 0][:26]
    config = RunConfig(edge_beads=5, impacts=[{"site": site, "v0": 0.1 + 0.01 * k} for k, site in enumerate(interior)])
    model = build_model(config)
    with pytest.raises(HexdemError, match="LAMMPS groups"):
        render_input(model, run_settings(config, model))


def test_extra_observation_lines_follow_the_lattice_from_any_bead(tmp_path):
    config = RunConfig(
        edge_beads=5,
        engine="reference",
        lines=[{"name": "up", "site": [-8, 4], "angle_deg": 90}, {"name": "sixty", "site": [0, 0], "angle_deg": 60}],
    )
    lattice = build_packing(config)
    assert [tuple(lattice.labels[b]) for b in lattice.line("up")] == [(m, 4) for m in range(-8, 9, 2)]
    assert [tuple(lattice.labels[b]) for b in lattice.line("sixty")] == [(0, 0), (3, 1), (6, 2)]
    run_experiment(config, tmp_path, log=lambda message: None)
    assert json.loads((tmp_path / "summary.json").read_text())["impacts"] == [
        {"bead_id": lattice.struck + 1, "site": [0, 0], "v0": 0.4, "angle_deg": 0.0, "kind": "velocity"}
    ]
    header, rows = read_csv(tmp_path / "peaks.csv")
    assert [row["line"] for row in rows if row["line"] in ("0", "+30", "-30")] == [
        row["line"] for row in rows[: sum(len(lattice.line(n)) for n in ("0", "+30", "-30"))]
    ]
    assert [int(row["n"]) for row in rows if row["line"] == "up"] == list(range(9))


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"impacts": [{"site": [0, 30]}]}, "not in the packing"),
        ({"impacts": [{"site": [0, 0]}, {"site": [0, 0], "angle_deg": 10.0}]}, "two impacts strike the same bead"),
        ({"impacts": [{"site": [0, 0]}, {"site": [0, 10], "kind": "striker"}]}, "would start inside bead"),
        ({"impacts": [{"site": [0, 0], "edge_deg": 0.0}]}, "exactly one of site"),
        ({"impacts": [{"site": [0, 0], "speed": 1.0}]}, "unknown key(s) speed"),
        ({"impacts": [{"site": [0, 0], "kind": "hammer"}]}, "unknown kind 'hammer'"),
        ({"impacts": [{"site": [0, 0], "v0": -1.0}]}, "v0 must be > 0"),
        ({"impacts": [{"site": [0, 0], "striker_material": "unobtainium", "kind": "striker"}]}, "unobtainium"),
        (
            {"precompression_n": 5.0, "impacts": [{"site": [0, 0]}, {"site": [0, 20], "angle_deg": 180.0}]},
            "precompressed packing holds only",
        ),
        ({"lines": [{"name": "0", "site": [0, 0], "angle_deg": 90}]}, "must be a new"),
        ({"lines": [{"name": "up", "site": [0, 0], "angle_deg": 45}]}, "not a lattice direction"),
        ({"lines": [{"name": "up", "site": [1, 0], "angle_deg": 90}]}, "is not a bead"),
        ({"lines": [{"name": "up", "site": [[0], 0], "angle_deg": 90}]}, "lines.0.site must be a list of 2 integers"),
        ({"impacts": [{"edge_deg": 30.0}]}, "no flat edge"),
        ({"impacts": [{"site": [0, 0], "angle_deg": 150.0}]}, "points out of the packing through wall_000"),
    ],
)
def test_bad_impacts_and_lines_get_one_line_errors(changes, message):
    with pytest.raises(HexdemError, match=None) as error:
        build_model(RunConfig(**changes))
    assert message in str(error.value) and "\n" not in str(error.value)


def test_the_far_wall_of_every_impact_must_be_reached():
    """A double strike from both ends of the hexagon's middle row: each impact's far wall is the
    other's struck wall, so a run in which the left wall's beads are reached only at the very
    end (the second impact's wave still crossing) has not reached its far walls, whatever the
    first impact's far wall says."""
    from hexdem.analysis.energy import energy_regions
    from hexdem.analysis.impact import ImpactAnalysis

    config = RunConfig(impacts=[{"site": [0, 0]}, {"site": [0, 20], "angle_deg": 180.0}])
    model = build_model(config)
    settings = run_settings(config, model)
    n = len(model.packing)
    left = next(w for w in model.walls if w.normal[0] > 0.99)

    def far_wall_reached(reach_time):
        regions = len(energy_regions(model)[0])
        return ImpactAnalysis(
            model,
            settings,
            {},
            np.ones(n),
            np.zeros(n),
            np.zeros(n),
            reach_time,
            0.0,
            (np.zeros(1), np.zeros((1, regions, 2))),
            np.zeros((n, 2)),
        ).results.far_wall_reached

    reach = np.zeros(n)
    assert far_wall_reached(reach)
    reach[left.members] = settings.duration_s / settings.units.time_s
    assert not far_wall_reached(reach)
