"""The prestress of a packing (hexdem.disorder.prestress) against Hertz's law by hand."""

from dataclasses import replace

import numpy as np
import pytest

from hexdem.disorder.prestress import prestress, touching_pairs
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model


def test_a_touching_ideal_lattice_carries_no_load():
    model = build_model(RunConfig())
    load = prestress(model)
    assert load.contacts == 0 and load.mean_contact_force_n == 0 and load.wall_force_n == 0


def test_pair_forces_follow_hertz_with_each_contacts_own_radius():
    """Shrink the lattice so that neighbours overlap by δ: every bond carries k sqrt(R_eff) δ^1.5,
    R_eff = r/2 for equal beads."""
    model = build_model(RunConfig())
    lattice = model.packing
    d, delta = lattice.diameter_m, 1e-6
    squeezed = replace(model, packing=replace(lattice, positions_m=lattice.positions_m * (d - delta) / d))
    i, j, overlap = touching_pairs(squeezed.packing.positions_m, lattice.diameters_m)
    np.testing.assert_allclose(overlap, delta, rtol=1e-6)
    assert len(i) == 9 * 11**2 - 15 * 11 + 6  # the bonds of a hexagon of 11 beads per edge
    load = prestress(squeezed)
    expected = model.stiffness_table_pa[0, 0] * np.sqrt(d / 4) * delta**1.5
    assert load.contacts == len(i)
    assert load.max_overlap_m == pytest.approx(delta, rel=1e-6)
    assert load.mean_contact_force_n == pytest.approx(expected, rel=1e-5)
    assert load.max_contact_force_n == pytest.approx(expected, rel=1e-5)


def test_a_wall_pushed_in_by_delta_loads_each_of_its_beads_by_hertz():
    model = build_model(RunConfig())
    lattice = model.packing
    delta = 2e-6
    wall = lattice.walls[0]
    pushed = replace(
        model, packing=replace(lattice, walls=(replace(wall, offset_m=wall.offset_m + delta), *lattice.walls[1:]))
    )
    load = prestress(pushed)
    per_bead = model.wall_stiffness_pa([0])[0] * np.sqrt(lattice.diameter_m / 2) * delta**1.5
    assert load.contacts == 0
    assert load.wall_force_n == pytest.approx(len(wall.members) * per_bead, rel=1e-6)
