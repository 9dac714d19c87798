"""Geometry of the packings: bead counts, touching bonds, lines, walls, labels."""

import numpy as np
import pytest

from hexdem.errors import HexdemError
from hexdem.model.lattice import half_disc, half_hexagon, hexagon, strike_direction

D = 0.01905


@pytest.mark.parametrize("edge", [2, 3, 11])
def test_hexagon_bead_count_is_centred_hexagonal_number(edge):
    assert len(hexagon(edge, D)) == 3 * edge * (edge - 1) + 1


def test_half_hexagon_of_fig4_holds_half_the_hexagon_plus_its_diagonal():
    full = hexagon(46, D)
    assert len(half_hexagon(91, 46, D)) == (len(full) + 91) // 2 == 3151


@pytest.mark.parametrize("lattice", [hexagon(11, D), half_hexagon(21, 11, D)], ids=["hexagon", "half"])
def test_bonds_are_touching_and_labels_follow_the_paper(lattice):
    i, j = lattice.bonds().T
    lengths = np.linalg.norm(lattice.positions_m[i] - lattice.positions_m[j], axis=1)
    np.testing.assert_allclose(lengths, D, rtol=1e-12)
    assert np.all(lattice.indices.sum(axis=1) % 2 == 0)
    distances = np.linalg.norm(lattice.positions_m[:, None] - lattice.positions_m[None], axis=2)
    touching = np.sum(np.isclose(distances, D, rtol=1e-9)) // 2
    assert touching == len(i), "every touching pair is exactly one bond"


def test_interior_beads_have_six_neighbours():
    lattice = hexagon(5, D)
    counts = np.bincount(lattice.bonds().ravel(), minlength=len(lattice))
    assert counts.max() == 6 and counts[lattice.index_of(0, 4)] == 6
    assert counts[lattice.struck] == 4, "edge centre: two edge neighbours, two at +-30 deg"


def test_observation_lines_have_the_papers_spacings():
    lattice = hexagon(11, D)
    for name, spacing in (("0", np.sqrt(3) * D), ("+30", D), ("-30", D)):
        beads = lattice.line(name)
        steps = np.diff(lattice.positions_m[beads], axis=0)
        np.testing.assert_allclose(np.linalg.norm(steps, axis=1), spacing, rtol=1e-12)
        assert beads[0] == lattice.struck
    angles = {name: np.degrees(np.arctan2(*np.diff(lattice.positions_m[lattice.line(name)][:2], axis=0)[0][::-1]))
              for name in ("0", "+30", "-30")}
    assert angles == pytest.approx({"0": 0.0, "+30": 30.0, "-30": -30.0})
    assert len(lattice.line("0")) == 11


def test_walls_touch_without_compressing_and_leave_a_hole_at_the_struck_bead():
    lattice = hexagon(11, D)
    assert len(lattice.walls) == 6
    for wall in lattice.walls:
        gaps = wall.gaps_m(lattice.positions_m, lattice.radii_m)
        assert gaps.min() == pytest.approx(0.0, abs=1e-15)
        assert len(wall.members) == 11 - (wall.name == "wall_000")
    struck_wall = next(w for w in lattice.walls if w.name == "wall_000")
    assert lattice.struck not in struck_wall.members


def test_strike_direction_and_bad_angles():
    np.testing.assert_allclose(strike_direction(30), [np.sqrt(3) / 2, 0.5])
    for bad in (90, -120, float("nan")):
        with pytest.raises(HexdemError, match="strike angle"):
            strike_direction(bad)


@pytest.mark.parametrize("bad", [1, 0, -3, 2.5])
def test_too_few_edge_beads_is_an_error(bad):
    with pytest.raises(HexdemError, match="at least 2 beads per edge"):
        hexagon(bad, D)


def test_half_hexagon_edges_must_match():
    with pytest.raises(HexdemError, match="long_edge"):
        half_hexagon(90, 46, D)


def test_a_protruding_struck_bead_sits_in_the_hole_and_does_not_move_its_wall():
    lattice = hexagon(5, D)
    diameters = lattice.diameters_m.copy()
    diameters[lattice.struck] *= 1.01
    grown = lattice.with_geometry(lattice.positions_m, diameters)
    struck_wall = next(w for w in grown.walls if w.name == "wall_000")
    assert struck_wall.offset_m == pytest.approx(-D / 2)
    assert struck_wall.gaps_m(grown.positions_m[lattice.struck], grown.radii_m[lattice.struck]) < 0


def test_half_disc_holds_every_site_within_its_radius_on_the_struck_side():
    """Radius 12: every lattice site {m, n} (m + n even, n >= 0) within 12 d of the struck bead,
    and no other; one wall, the struck edge's, touching the n = 0 beads but the struck one."""
    lattice = half_disc(12, 1.0)
    expected = {(m, n) for n in range(0, 15) for m in range(-24, 25)
                if (m + n) % 2 == 0 and 0.75 * n**2 + 0.25 * m**2 <= 144 + 1e-9}
    assert {tuple(mn) for mn in lattice.indices.tolist()} == expected
    assert np.hypot(*lattice.positions_m.T).max() <= 12.0 + 1e-12
    (wall,) = lattice.walls
    assert wall.normal == (1.0, 0.0) and wall.offset_m == pytest.approx(-0.5)
    assert set(wall.members.tolist()) == set(np.flatnonzero(lattice.indices[:, 1] == 0)) - {lattice.struck}
    assert len(lattice.line("0")) == 7 and len(lattice.line("+30")) == 13
