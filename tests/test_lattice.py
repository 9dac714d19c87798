"""Geometry of the packings: bead counts, touching bonds, lines, walls, labels."""

import numpy as np
import pytest

from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.packing import strike_direction
from hexdem.model.triangular import (
    disc,
    from_sites,
    half_disc,
    half_hexagon,
    hexagon,
    parallelogram,
    triangle,
    without_sites,
)

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
    assert np.all(lattice.labels.sum(axis=1) % 2 == 0)
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
    angles = {
        name: np.degrees(np.arctan2(*np.diff(lattice.positions_m[lattice.line(name)][:2], axis=0)[0][::-1]))
        for name in ("0", "+30", "-30")
    }
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
    expected = {
        (m, n)
        for n in range(0, 15)
        for m in range(-24, 25)
        if (m + n) % 2 == 0 and 0.75 * n**2 + 0.25 * m**2 <= 144 + 1e-9
    }
    assert {tuple(mn) for mn in lattice.labels.tolist()} == expected
    assert np.hypot(*lattice.positions_m.T).max() <= 12.0 + 1e-12
    (wall,) = lattice.walls
    assert wall.normal == (1.0, 0.0) and wall.offset_m == pytest.approx(-0.5)
    assert set(wall.members.tolist()) == set(np.flatnonzero(lattice.labels[:, 1] == 0)) - {lattice.struck}
    assert len(lattice.line("0")) == 7 and len(lattice.line("+30")) == 13


@pytest.mark.parametrize("edge", [3, 4, 11])
def test_triangle_holds_a_triangular_number_of_beads_with_three_walls(edge):
    """N per edge: N(N + 1)/2 beads; the struck edge (x = 0) and the two edges at ±60° from it
    each hold N beads, every one touching its wall (the struck bead in its hole)."""
    lattice = triangle(edge, D)
    assert len(lattice) == edge * (edge + 1) // 2
    assert tuple(lattice.labels[lattice.struck]) == (0, 0)
    apex = lattice.positions_m[:, 0].max()
    assert apex == pytest.approx(np.sqrt(3) / 2 * (edge - 1) * D)
    for wall in lattice.walls:
        gaps = wall.gaps_m(lattice.positions_m[wall.members], lattice.radii_m[wall.members])
        np.testing.assert_allclose(gaps, 0.0, atol=1e-15)
        assert len(wall.members) == edge - (wall.name == "wall_000")
    assert sorted(w.name for w in lattice.walls) == ["wall_000", "wall_120", "wall_m120"]


def test_parallelogram_has_equal_layers_sheared_along_30_degrees():
    lattice = parallelogram(5, 7, D)
    assert len(lattice) == 35
    layers = np.bincount(lattice.labels[:, 1])
    assert list(layers) == [5] * 7
    lowest = [lattice.labels[lattice.labels[:, 1] == n, 0].min() for n in range(7)]
    assert np.all(np.diff(lowest) == 1), "each layer one half-diameter higher: edges at +30 deg"
    counts = {wall.name: len(wall.members) for wall in lattice.walls}
    assert counts == {"wall_000": 4, "wall_180": 5, "wall_120": 7, "wall_m60": 7}
    i, j = lattice.bonds().T
    np.testing.assert_allclose(np.linalg.norm(lattice.positions_m[i] - lattice.positions_m[j], axis=1), D)


def test_listed_sites_are_the_packing_and_their_walls_touch_it():
    sites = [(0, 0), (2, 0), (-2, 0), (1, 1), (-1, 1), (0, 2)]
    lattice = from_sites(sites, D, (0,), "six")
    assert [tuple(mn) for mn in lattice.labels.tolist()] == sites
    (wall,) = lattice.walls
    assert set(wall.members.tolist()) == {1, 2}, "the n = 0 beads but the struck one"


@pytest.mark.parametrize(
    "sites, message",
    [
        ([(0, 0), (2, 0), (0, 0)], "listed twice"),
        ([(0, 0), (1, 0)], "m [+] n odd"),
        ([(2, 0), (4, 0)], "struck site"),
        ([], "at least 1 bead"),
    ],
)
def test_bad_site_lists_are_refused(sites, message):
    with pytest.raises(HexdemError, match=message):
        from_sites(sites, D)


def test_vacancies_leave_sites_out_and_keep_the_walls():
    full = hexagon(5, D)
    holed = without_sites(full, [(1, 1), (4, 4)])
    assert len(holed) == len(full) - 2
    assert holed.index_of(1, 1) is None and holed.index_of(4, 4) is None
    assert tuple(holed.labels[holed.struck]) == (0, 0)
    for before, after in zip(full.walls, holed.walls):
        assert after.offset_m == before.offset_m
        kept = [tuple(full.labels[i]) for i in before.members if tuple(full.labels[i]) not in {(1, 1), (4, 4)}]
        assert [tuple(holed.labels[i]) for i in after.members] == kept
    bonds = {tuple(sorted(map(tuple, holed.labels[pair]))) for pair in holed.bonds()}
    assert not any((1, 1) in bond or (4, 4) in bond for bond in bonds)
    with pytest.raises(HexdemError, match="struck bead cannot be a vacancy"):
        without_sites(full, [(0, 0)])
    with pytest.raises(HexdemError, match="not a site"):
        without_sites(full, [(40, 0)])


def test_config_reads_sites_from_csv_and_toml(tmp_path):
    csv_file, toml_file = tmp_path / "sites.csv", tmp_path / "sites.toml"
    csv_file.write_text("m,n\n0,0\n2,0\n1,1\n")
    toml_file.write_text("sites = [[0, 0], [2, 0], [1, 1]]\n")
    inline = build_packing(RunConfig(shape="sites", sites=[[0, 0], [2, 0], [1, 1]]))
    for path in (csv_file, toml_file):
        lattice = build_packing(RunConfig(shape="sites", sites_file=str(path)))
        np.testing.assert_array_equal(lattice.labels, inline.labels)
        assert lattice.walls == ()
    (tmp_path / "bad.csv").write_text("m,n\n0,0\nx,1\n")
    with pytest.raises(HexdemError, match="two integers"):
        build_model(RunConfig(shape="sites", sites_file=str(tmp_path / "bad.csv")))
    with pytest.raises(HexdemError, match="exactly one of"):
        build_model(RunConfig(shape="sites"))


def test_disc_holds_every_site_within_its_radius_inside_a_touching_circle():
    """Radius 12: every site within 12 d of (12 d, 0) and no other; the circle touches the
    outermost beads (the struck bead, at the edge's centre, sits in its hole)."""
    lattice = disc(12, 1.0)
    expected = {
        (m, n)
        for n in range(0, 28)
        for m in range(-24, 25)
        if (m + n) % 2 == 0 and (np.sqrt(3) / 2 * n - 12) ** 2 + (m / 2) ** 2 <= 144 + 1e-9
    }
    assert {tuple(mn) for mn in lattice.labels.tolist()} == expected
    (wall,) = lattice.walls
    gaps = wall.gaps_m(lattice.positions_m, lattice.radii_m)
    others = np.delete(gaps, lattice.struck)
    assert others.min() == pytest.approx(0.0, abs=1e-12) and lattice.struck not in wall.members
    assert set(wall.members.tolist()) == set(np.flatnonzero(gaps < 0.25).tolist()) - {lattice.struck}
    np.testing.assert_allclose(np.linalg.norm(wall.normals_at(lattice.positions_m[wall.members]), axis=1), 1.0)


def test_packings_compare_by_identity_without_raising():
    """A packing of arrays is the same packing only as the same object: comparing two equal
    builds neither raises (as the arrays' elementwise == would) nor calls them equal."""
    packing = hexagon(3, 0.01)
    assert packing == packing
    assert packing != hexagon(3, 0.01)
    assert len({packing, packing, hexagon(3, 0.01)}) == 2


def test_label_lines_are_named():
    line = next(line for line in hexagon(3, 0.01).label_lines if line.name == "+30")
    assert line.start is None and line.step == line[2]
