"""Packings beyond the triangular lattice, checked by their physics in both engines: the square crystal's struck
row is a chain carrying Nesterenko's solitary wave, the centered-square crystal is symmetric
about its strike, an intruder in a chain splits the wave while momentum and energy are kept,
and a packing read from a file is the packing it was written from."""

from pathlib import Path

import numpy as np
import pytest

from hexdem.errors import HexdemError
from hexdem.experiments.compare import MARGIN, PEAK_ERROR_N2, PLACED_PEAK_ERROR_N2, Tolerances, run_comparison
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.model.materials import sphere_mass
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.run_settings import run_settings
from hexdem.model.solitary_wave import chain_speed_scale_m_s, solitary_speed_m_s
from hexdem.model.square_crystals import interstitial_fit_m

V0 = 0.4
GALLERY = Path(__file__).resolve().parent.parent / "docs" / "gallery" / "configs"
#: The square's struck row is read over these beads: the pulse has formed, the far wall is 2 beads on.
SQUARE_WINDOW = (5, 12)


@pytest.fixture(scope="module", params=["lammps", "reference"])
def square_run(request, tmp_path_factory):
    return simulate(
        RunConfig(shape="square", rows=15, columns=15, engine=request.param), tmp_path_factory.mktemp("square")
    )


def test_the_square_crystals_struck_row_carries_nesterenkos_solitary_wave(square_run):
    """Along "0" the beads touch head-on, as in a chain: the front runs at Nesterenko's
    V_s = (16/25)^(1/5) c^(4/5) V_m^(1/5) within 1.5 %, on the slow side (the discrete chain lags the
    continuum law by its first dropped finite-difference term, 0.7 %); its neighbours touch it at
    90°, where a normal force has no component along the row, so no other bead moves."""
    r, model = square_run.results, square_run.model
    row = r.lines["0"]
    n = np.arange(*SQUARE_WINDOW)
    speed = np.polyfit(r.arrival_time[row[n]], n * model.packing.diameter_m, 1)[0]
    peak = float(np.mean(r.peak_speed[row[n]]))
    law = solitary_speed_m_s(chain_speed_scale_m_s(model.bead), peak)
    assert -0.015 < speed / law - 1 < 0
    off_row = model.packing.labels[:, 0] != 0
    assert np.all(r.peak_speed[off_row] == 0.0)  # never moved: not NaN, not round-off


def test_an_oblique_strike_sends_motion_up_the_struck_column(tmp_path, square_run):
    """At 5° the struck bead pushes the bead above it head-on with its V0 sin 5° (no bead above
    moves at 0°): that bead takes at least half of it."""
    tilted = simulate(
        RunConfig(shape="square", rows=15, columns=15, strike_angle_deg=5.0, engine=square_run.engine["name"]), tmp_path
    )
    above = tilted.results.lines["+90"][1]
    assert tilted.results.peak_speed[above] > 0.5 * V0 * np.sin(np.radians(5.0))
    assert square_run.results.peak_speed[above] == 0.0


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_the_centered_square_crystal_is_symmetric_about_its_strike(tmp_path, engine):
    """Mirrored in the strike axis (label {m, n} to {−m, n}), every bead peaks and arrives as its image."""
    analysis = simulate(
        RunConfig(shape="centered-square", rows=7, columns=7, interstitial_material="brass", engine=engine), tmp_path
    )
    r, labels = analysis.results, analysis.model.packing.labels
    image = [analysis.model.packing.index_of(-m, n) for m, n in labels.tolist()]
    np.testing.assert_allclose(r.peak_speed[image], r.peak_speed, rtol=1e-9, atol=1e-12)
    moved = np.isfinite(r.arrival_time)
    assert moved.sum() > len(labels) // 2
    np.testing.assert_allclose(r.arrival_time[image][moved], r.arrival_time[moved], rtol=1e-9)
    small = analysis.model.packing.diameters_m < analysis.model.packing.diameter_m
    assert np.allclose(analysis.model.packing.diameters_m[small], interstitial_fit_m(analysis.model.packing.diameter_m))
    assert {m.name for m in analysis.model.materials} == {"steel316", "brass"}


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_a_light_intruder_splits_the_chains_wave_and_keeps_momentum_and_energy(tmp_path, engine):
    """A bead of half the diameter (an eighth of the mass) in the middle of a free chain: most of the
    solitary wave's energy goes on past it (measured: 94 %), part comes back, and the chain's
    momentum m V0 and energy are those the impact gave it."""
    beads, intruder, d = 40, 20, 0.01905
    sizes = np.full(beads, d)
    sizes[intruder] = d / 2
    analysis = simulate(
        RunConfig(shape="chain", beads=beads, diameters_m=sizes.tolist(), duration=2.0e-3, engine=engine), tmp_path
    )
    r, model = analysis.results, analysis.model
    masses = model.masses_kg[:beads]
    np.testing.assert_allclose(masses @ r.end_velocity, [masses[0] * V0, 0.0], atol=1e-9 * masses[0] * V0)
    assert r.energy_drift < 1e-4
    kinetic = 0.5 * masses * np.sum(r.end_velocity**2, axis=1)
    assert masses[:intruder] @ r.end_velocity[:intruder, 0] < 0, "part of the wave comes back"
    given = 0.5 * masses[0] * V0**2
    transmitted, reflected = kinetic[intruder + 1 :].sum() / given, kinetic[:intruder].sum() / given
    assert 0 < reflected < transmitted and transmitted + reflected <= 1 + r.energy_drift
    assert np.isfinite(r.arrival_time[beads - 1]), "the transmitted wave reaches the chain's end"


def test_a_packing_file_is_the_packing_it_was_written_from(tmp_path):
    """The default hexagon written as x, y, diameter with hull walls: the same beads, the same
    walls and holes, and the same peaks and arrivals on every bead the pulse reaches before it
    could meet a wall (1e-6)."""
    default = RunConfig()
    lattice = build_packing(default)
    rows = "\n".join(
        f"{float(x)!r},{float(y)!r},{float(d)!r}" for (x, y), d in zip(lattice.positions_m, lattice.diameters_m)
    )
    (tmp_path / "hexagon.csv").write_text("x,y,diameter\n" + rows + "\n")
    from_file = RunConfig(
        shape="packing", packing_file=str(tmp_path / "hexagon.csv"), walls="hull", struck_bead=int(lattice.struck)
    )
    packed = build_packing(from_file)
    np.testing.assert_allclose(
        sorted(np.round(w.normal, 12).tolist() for w in packed.walls),
        sorted(np.round(w.normal, 12).tolist() for w in lattice.walls),
        atol=1e-12,
    )
    assert sorted(sorted(w.members.tolist()) for w in packed.walls) == sorted(
        sorted(w.members.tolist()) for w in lattice.walls
    )
    a, b = (simulate(config, tmp_path / name).results for config, name in ((default, "lattice"), (from_file, "file")))
    early = a.arrival_time < 0.5 * np.nanmax(a.arrival_time)
    assert early.sum() > 50
    np.testing.assert_allclose(b.peak_speed[early], a.peak_speed[early], rtol=1e-6)
    np.testing.assert_allclose(b.arrival_time[early], a.arrival_time[early], rtol=1e-6)
    assert {name: len(beads) for name, beads in b.lines.items()} == {
        name: len(beads) for name, beads in a.lines.items()
    }


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"shape": "square", "rows": 0}, "at least 2 rows and 2 columns, got 0 x 15"),
        ({"shape": "square", "rows": 1, "columns": 1}, "at least 2 rows and 2 columns, got 1 x 1"),
        ({"shape": "centered-square", "rows": 1}, "at least 2 rows"),
        ({"shape": "sites", "sites": [[0, 0]]}, "a packing needs at least 2 beads, or 1 bead and a wall"),
        ({"shape": "chain", "beads": 3, "diameters_m": [0.01, 0.01]}, "2 diameters for a chain of 3"),
        ({"shape": "chain", "beads": 3, "bead_materials": ["brass", "glass"]}, "2 names for a chain of 3"),
        ({"shape": "chain", "beads": 2, "materials": ["brass"]}, "per bead goes in bead_materials"),
        ({"shape": "chain", "beads": 1}, "a chain needs beads >= 2"),
        ({"shape": "chain", "intruders": [{"bead": 20, "diameter_m": 0.01}]}, "bead from 0 to 19"),
        ({"shape": "chain", "intruders": [{"bead": 2}]}, "a diameter_m or a material"),
        ({"shape": "packing"}, "needs packing_file"),
        ({"shape": "hexagon", "packing_file": "x.csv"}, 'describes shape = "packing"'),
    ],
)
def test_bad_shapes_are_one_line_errors(changes, message):
    with pytest.raises(HexdemError, match=message) as error:
        build_model(RunConfig(**changes))
    assert "\n" not in str(error.value)


def test_overlapping_or_badly_written_packing_files_are_refused(tmp_path):
    path = tmp_path / "beads.csv"
    for text, message in (
        ("x,y\n0,0\n", "header line"),
        ("x,y,diameter\n0,0,0.019\n0.01,0,0.019\n", "overlap"),
        ("x,y,diameter\n0,0,abc\n", "finite numbers"),
        ("x,y,diameter\n0,0,0.1\n", "not within a factor 2"),
    ):
        path.write_text(text)
        with pytest.raises(HexdemError, match=message):
            build_model(RunConfig(shape="packing", packing_file=str(path)))


def test_a_chains_short_forms_equal_the_lists_typed_out():
    """A dimer's repeating pattern and an intruder's table give the chain of the whole lists."""
    d, small = 0.01905, 0.009525
    pairs = (
        (
            {"diameters_m": [d, small], "bead_materials": ["steel316", "brass"]},
            {"diameters_m": [d, small] * 5, "bead_materials": ["steel316", "brass"] * 5},
        ),
        (
            {"intruders": [{"bead": 5, "diameter_m": small, "material": "brass"}]},
            {"diameters_m": [d] * 5 + [small] + [d] * 4, "bead_materials": [""] * 5 + ["brass"] + [""] * 4},
        ),
    )
    for short, typed in pairs:
        a, b = (build_model(RunConfig(shape="chain", beads=10, **keys)) for keys in (short, typed))
        np.testing.assert_array_equal(a.packing.positions_m, b.packing.positions_m)
        np.testing.assert_array_equal(a.masses_kg, b.masses_kg)
        assert [m.name for m in a.materials] == [m.name for m in b.materials]
        assert a.materials[a.packing.material_ids[5]].name == "brass"


def test_a_chains_intruder_mass_follows_its_diameter():
    config = RunConfig(shape="chain", beads=3, diameters_m=[0.02, 0.01, 0.02])
    model = build_model(config)
    assert model.masses_kg[1] == pytest.approx(sphere_mass(0.01, model.bead))
    np.testing.assert_allclose(model.packing.positions_m[:, 0], [0.0, 0.015, 0.03])


@pytest.mark.parametrize(
    "changes",
    [
        {"shape": "square", "rows": 7, "columns": 9, "strike_angle_deg": 5.0},
        {"shape": "square", "rows": 7, "columns": 9, "strike_angle_deg": 20.0, "friction": 0.3},
        {"shape": "centered-square", "rows": 7, "columns": 9, "interstitial_material": "brass"},
        {"shape": "centered-square", "rows": 5, "columns": 7, "restitution": 0.9},
        {
            "shape": "chain",
            "beads": 30,
            "diameters_m": [0.01905] * 15 + [0.009525] + [0.01905] * 14,
            "duration": 1.5e-3,
        },
    ],
    ids=["square-oblique", "square-friction", "centered-square", "centered-square-damped", "chain-intruder"],
)
def test_both_engines_agree_on_every_packing(tmp_path, changes):
    """LAMMPS and the reference integrator, each finding its contacts from the geometry, agree at
    ``hexdem compare``'s default tolerances on every line of the packing (their peak tolerance
    from :data:`~hexdem.experiments.compare.PLACED_PEAK_ERROR_N2`)."""
    comparison = run_comparison(RunConfig(**changes), tmp_path, log=lambda message: None)
    assert comparison.agree, comparison.verdict()
    assert comparison.n_checked >= 10


def test_both_engines_agree_on_a_packing_file_with_rattlers_and_hull_walls(tmp_path):
    """The gallery's measured hexagon: five undersized rattlers, five brass beads, walls along its hull."""
    config = RunConfig.from_toml(GALLERY / "packing.toml")
    comparison = run_comparison(config, tmp_path, log=lambda message: None)
    assert comparison.agree, comparison.verdict()
    assert {row[0] for row in comparison.rows} == {"0", "+30", "-30"}


def test_compares_peak_tolerance_off_the_triangular_lattice_is_the_measured_one():
    """MARGIN times 5.0/N² on a square (the largest error measured off the lattice), 0.8/N² on the hexagon."""
    for config, coefficient in (
        (RunConfig(shape="square", rows=5, columns=5), PLACED_PEAK_ERROR_N2),
        (RunConfig(edge_beads=4), PEAK_ERROR_N2),
    ):
        model = build_model(config)
        settings = run_settings(config, model)
        steps = settings.contact_time_s / settings.dt_s
        assert Tolerances().for_run(model, settings).peak_rel == pytest.approx(MARGIN * coefficient / steps**2)


def test_a_chain_is_struck_along_itself_by_default(tmp_path):
    """Turned to 180°, the default strike follows the chain (it once went along +x, and bead 0 flew
    away): the pulse is the same as along +x, mirrored."""
    along, turned = (
        simulate(RunConfig(shape="chain", beads=6, angle_deg=angle, engine="reference"), tmp_path / str(angle)).results
        for angle in (0.0, 180.0)
    )
    assert turned.peak_speed[-1] > 0.5 * along.peak_speed[0]
    np.testing.assert_allclose(turned.peak_speed, along.peak_speed, rtol=1e-9)


def test_a_packing_file_is_read_with_its_byte_order_mark_and_from_the_configs_folder(tmp_path, monkeypatch):
    """A CSV saved with a UTF-8 byte-order mark (was: 'the header must be x,y,diameter'), and a
    relative packing_file, which hexdem sweep read from the current directory, from the config's
    folder as hexdem run reads it."""
    from hexdem.experiments.sweep_plan import Variation, plan_sweep, read_base

    folder = tmp_path / "study"
    folder.mkdir()
    (folder / "beads.csv").write_text("x,y,diameter\n0.0,0.0,0.01905\n0.01905,0.0,0.01905\n", encoding="utf-8-sig")
    assert (folder / "beads.csv").read_bytes().startswith(b"\xef\xbb\xbf")
    (folder / "base.toml").write_text('shape = "packing"\npacking_file = "beads.csv"\nwalls = "none"\n')
    monkeypatch.chdir(tmp_path)
    runs = plan_sweep(read_base(folder / "base.toml"), [Variation.parse("v0=0.3,0.4")])
    assert {run.config.packing_file for run in runs} == {str(folder / "beads.csv")}
    assert len(build_model(runs[0].config).packing) == 2
