"""Beads of unlike materials: Hertz contacts with the pair's own E* and R_eff, in both engines.

A striker of one material and size hitting a lone bead of another is the yardstick: Hertz's
contact time with μ = m₁m₂/(m₁ + m₂), A = (4/3) E* sqrt(R_eff), 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂,
1/R_eff = 1/R₁ + 1/R₂, and afterwards the elastic head-on velocities
v₁' = (m₁ − m₂)/(m₁ + m₂) V₀, v₂' = 2m₁/(m₁ + m₂) V₀ (momentum and energy conserved).
"""

import numpy as np
import pytest
from conftest import V0, D, contact_history, read_csv, record, single_bead

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.errors import HexdemError
from hexdem.experiments.run import ENERGY_REGION_COLUMNS, run_experiment, simulate
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.materials import BRASS, PTFE, STEEL_316
from hexdem.model.model_builder import build_model

STRIKER_D = 0.6 * D


def by_hand(a, b, da, db):
    """(m_a, m_b, A) of a head-on contact of spheres of materials a, b and diameters da, db."""
    ma, mb = (m.density_kg_m3 * np.pi * d**3 / 6 for m, d in ((a, da), (b, db)))
    e_star = 1.0 / ((1 - a.poisson_ratio**2) / a.youngs_modulus_pa + (1 - b.poisson_ratio**2) / b.youngs_modulus_pa)
    r_eff = 1.0 / (2 / da + 2 / db)
    return ma, mb, 4.0 / 3.0 * e_star * np.sqrt(r_eff)


@pytest.mark.parametrize("engine", [LammpsEngine(), ReferenceEngine()], ids=lambda e: e.name)
@pytest.mark.parametrize("striker", [BRASS, PTFE], ids=lambda m: m.name)
def test_a_striker_of_another_material_and_size_leaves_as_momentum_and_energy_say(engine, striker, tmp_path):
    model = GranularModel(
        single_bead(D),
        Impact(V0, striker=True, striker_material=striker, striker_diameter_m=STRIKER_D),
        STEEL_316,
        wall=None,
    )
    m1, m2, a = by_hand(striker, STEEL_316, STRIKER_D, D)
    mu = m1 * m2 / (m1 + m2)
    delta_max = (5 * mu * V0**2 / (4 * a)) ** 0.4
    expected = 2.9432653 * delta_max / V0  # (4/5) B(2/5, 1/2) δ_max / V0
    dt = expected / 2000
    trajectory = record(engine, model, RunSettings(dt, int(1.2 * expected / dt), 1), tmp_path)
    start = model.initial_positions_m()
    gap = np.linalg.norm(
        (start[1] + trajectory.displacements_m[:, 1]) - (start[0] + trajectory.displacements_m[:, 0]), axis=1
    )
    duration, peak = contact_history(trajectory.times_s, (STRIKER_D + D) / 2 - gap)
    assert duration == pytest.approx(expected, rel=3e-4)
    assert peak == pytest.approx(delta_max, rel=3e-4)
    final = trajectory.velocities_m_s[-1]
    np.testing.assert_allclose(final[:, 0], [2 * m1 / (m1 + m2) * V0, (m1 - m2) / (m1 + m2) * V0], atol=2e-5 * V0)
    assert model.masses_kg[1] == pytest.approx(m1)


def test_regions_give_materials_half_plane_strip_and_intruders():
    config = RunConfig(
        edge_beads=7,
        regions=[
            {"material": "brass", "x_min_d": 5.0},
            {"material": "glass", "x_min_d": 2.0, "x_max_d": 3.0},
            {"material": "ptfe", "sites": [[0, 6], [1, 7]]},
        ],
    )
    model = build_model(config)
    assert [m.name for m in model.materials] == ["steel316", "brass", "glass", "ptfe"]
    x_d = (model.packing.positions_m[:, 0] - model.packing.positions_m[model.packing.struck, 0]) / D
    names = np.array([model.materials[k].name for k in model.packing.material_ids])
    intruders = [model.packing.index_of(0, 6), model.packing.index_of(1, 7)]
    assert set(names[intruders]) == {"ptfe"}
    rest = np.setdiff1d(np.arange(len(names)), intruders)
    expected = np.where(
        x_d[rest] >= 5.0 - 1e-9,
        "brass",
        np.where((x_d[rest] >= 2.0 - 1e-9) & (x_d[rest] <= 3.0 + 1e-9), "glass", "steel316"),
    )
    np.testing.assert_array_equal(names[rest], expected)
    assert model.masses_kg[intruders[0]] == pytest.approx(PTFE.density_kg_m3 * np.pi * D**3 / 6)


@pytest.mark.parametrize(
    "regions, message",
    [
        ([{"material": "unobtainium", "x_min_d": 1.0}], "unknown material 'unobtainium'"),
        ([{"material": "brass", "sites": [[40, 2]]}], "site {40, 2} is not in the packing"),
        ([{"material": "brass", "x_min_d": 99.0}], "selects no bead"),
        ([{"material": "brass"}], "selects nothing"),
        ([{"material": "brass", "z_min_d": 1.0}], "unknown key(s) z_min_d"),
    ],
)
def test_bad_regions_are_refused(regions, message):
    with pytest.raises(HexdemError, match=message.replace("(", r"\(").replace(")", r"\)").replace("{", r"\{")):
        build_model(RunConfig(edge_beads=4, regions=regions))


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_energy_is_conserved_across_an_interface_struck_by_a_striker_of_its_own(engine, tmp_path):
    """Steel | brass at 3 d, a ptfe intruder, a glass striker: the total energy with each pair's
    own Hertz energy stays put (Verlet at 140 steps: 0.9/140² ≈ 5e-5; RK4 far below)."""
    config = RunConfig(
        edge_beads=6,
        engine=engine,
        impact="striker",
        striker_material="glass",
        regions=[{"material": "brass", "x_min_d": 3.0}, {"material": "ptfe", "sites": [[0, 4]]}],
    )
    results = simulate(config, tmp_path).results
    assert results.far_wall_reached
    assert results.energy_drift < (1e-4 if engine == "lammps" else 1e-6)


@pytest.mark.parametrize("impact", ["velocity", "striker"])
def test_energy_by_region_adds_up_to_the_impact_and_starts_in_the_struck_region(impact, tmp_path):
    """Steel | ptfe at 3 d: each audited time's kinetic + contact energy over all regions is the
    impact's energy (to the run's drift); at t = 0 it all sits in the struck bead's region (the
    striker's own, with one), and the ptfe side gets its share only once the front is there."""
    config = RunConfig(edge_beads=6, impact=impact, regions=[{"material": "ptfe", "x_min_d": 3.0}])
    analysis = run_experiment(config, tmp_path, log=lambda message: None)
    r = analysis.results
    totals = r.region_energies.sum(axis=(1, 2))
    np.testing.assert_allclose(totals, totals[0], rtol=2 * r.energy_drift + 1e-12)
    assert totals[0] == pytest.approx(
        0.5 * analysis.model.masses_kg[-1 if impact == "striker" else 0] * V0**2, rel=1e-12
    )
    first = "striker" if impact == "striker" else "steel316"
    assert r.region_names == ["steel316", "ptfe", *(["striker"] if impact == "striker" else [])]
    shares = r.region_energies.sum(axis=2) / totals[:, None]
    assert shares[0, r.region_names.index(first)] == pytest.approx(1.0, abs=1e-12)
    ptfe = r.region_names.index("ptfe")
    reached = np.nanmin(r.arrival_time[analysis.model.packing.material_ids == 1])
    assert np.all(shares[r.region_times < 0.25 * reached, ptfe] < 1e-9) and shares[-1, ptfe] > 0.05
    header, rows = read_csv(tmp_path / "energy_regions.csv")
    assert header == ENERGY_REGION_COLUMNS and len(rows) == len(r.region_times) * len(r.region_names)
    assert (tmp_path / "energy_regions.png").exists()
