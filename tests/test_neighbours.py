"""The reference engine's contacts come from a neighbour search (hexdem.engines.reference.neighbours),
not from fixed lattice bonds: any packing runs, contacts close and open during a run, and the list's
rebuilds change nothing."""

import numpy as np
import pytest
from conftest import V0, D, record

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.reference import contacts
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.engines.reference.neighbours import candidate_pairs, carried_over, skin_of
from hexdem.experiments.compare import Tolerances
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.hertz import contact_time
from hexdem.model.materials import STEEL_316, hertz_stiffness, sphere_mass
from hexdem.model.model_builder import build_model
from hexdem.model.packing import Packing
from hexdem.model.run_settings import run_settings

#: Steel beads of the experiment at V0: the two-bead Hertz contact time [s].
TAU = contact_time(sphere_mass(D, STEEL_316) / 2, hertz_stiffness(STEEL_316, STEEL_316) * np.sqrt(D / 4), V0)


def packing(positions_m, struck: int, shape: str) -> Packing:
    """Beads of diameter D at ``positions_m``, labelled 0, 1, … (the engines use positions only)."""
    n = len(positions_m)
    return Packing(
        labels=np.column_stack([np.arange(n), np.zeros(n, int)]),
        positions_m=np.asarray(positions_m, float),
        diameters_m=np.full(n, D),
        diameter_m=D,
        struck=struck,
        walls=(),
        shape=shape,
    )


def square(rows: int, cols: int) -> tuple[GranularModel, np.ndarray]:
    """A square packing (x = j D, y = i D), struck head-on at the middle of its left column: the
    model and the struck row's beads, left to right."""
    i, j = np.divmod(np.arange(rows * cols), cols)
    middle = rows // 2
    lattice = packing(np.column_stack([j, i]) * D, middle * cols, f"square, {rows} x {cols}")
    return GranularModel(lattice, Impact(V0), STEEL_316, wall=None), np.flatnonzero(i == middle)


def test_candidates_are_the_pairs_closer_than_the_skin():
    positions = np.array([[0.0, 0.0], [1.0, 0.0], [2.05, 0.0], [3.2, 0.0], [0.0, 1.5]])
    pairs = candidate_pairs(positions, np.full(5, 0.5), skin=0.1)
    np.testing.assert_array_equal(pairs, [[0, 1], [1, 2]])  # gaps 0 and 0.05; 0.15 and 0.5 are beyond it
    assert skin_of([1.0, 0.5, 2.0]) == pytest.approx(0.05)
    histories = carried_over(pairs, [3.0, 4.0], np.array([[1, 2], [2, 3]]))
    np.testing.assert_array_equal(histories, [4.0, 0.0])  # {1, 2} keeps its value, {2, 3} starts at 0


def test_a_square_packing_carries_the_pulse_along_its_struck_row_as_a_chain(tmp_path):
    """Fixed triangular bonds could not hold this packing. Listed: its 2 N (N − 1) square neighbours
    (the diagonal ones, 0.41 d apart, are not). Struck along a row, only that row moves: its
    vertical contacts open as its beads move along x. The row moves as a lone chain of its beads."""
    model, row = square(7, 12)
    settings = RunSettings(TAU / 140, 20 * 140, 7)
    grid = record(ReferenceEngine(), model, settings, tmp_path / "square")
    assert grid.engine["n_pairs"] == 2 * 7 * 12 - 7 - 12
    chain_model = GranularModel(packing(model.packing.positions_m[row], 0, "chain"), Impact(V0), STEEL_316, wall=None)
    chain = record(ReferenceEngine(), chain_model, settings, tmp_path / "chain")
    np.testing.assert_allclose(grid.velocities_m_s[:, row], chain.velocities_m_s, rtol=0, atol=1e-12 * V0)
    others = np.setdiff1d(np.arange(model.n_bodies), row)
    assert np.abs(grid.velocities_m_s[:, others]).max() < 1e-12 * V0
    assert chain.velocities_m_s[-1, -1, 0] > 0.5 * V0  # the pulse has crossed the row


def test_two_beads_that_start_apart_collide_and_part(tmp_path):
    """Bead 1 starts 0.2 d from bead 2 (beyond the skin: not listed at t = 0); the list is rebuilt as
    it closes in, the contact closes, lasts the two-bead Hertz contact time and opens; the equal beads
    exchange their velocities."""
    model = GranularModel(packing([[0.0, 0.0], [1.2 * D, 0.0]], 0, "two beads apart"), Impact(V0), STEEL_316, wall=None)
    approach = 0.2 * D / V0
    settings = RunSettings(TAU / 280, int((approach + 1.3 * TAU) / (TAU / 280)), 1)
    trajectory = record(ReferenceEngine(), model, settings, tmp_path)
    assert trajectory.engine["n_pairs"] == 0 and trajectory.engine["n_list_builds"] > 1
    centres = model.initial_positions_m() + trajectory.displacements_m
    overlap = D - np.linalg.norm(centres[:, 1] - centres[:, 0], axis=1)
    times = trajectory.times_s
    start, end = np.flatnonzero(overlap > 0)[[0, -1]]
    closes = np.interp(0.0, overlap[[start - 1, start]], times[[start - 1, start]])
    opens = np.interp(0.0, overlap[[end + 1, end]], times[[end + 1, end]])
    assert closes == pytest.approx(approach, rel=1e-6)
    assert opens - closes == pytest.approx(TAU, rel=1e-4)
    np.testing.assert_allclose(trajectory.velocities_m_s[-1], [[0.0, 0.0], [V0, 0.0]], atol=1e-7 * V0)


@pytest.mark.parametrize("friction", [0.0, 0.3], ids=["frictionless", "frictional"])
def test_rebuilding_the_list_often_changes_nothing(tmp_path, monkeypatch, friction):
    """A skin of 1e-5 d rebuilds the list hundreds of times during a striker's oblique impact; a listed
    pair that does not touch adds nothing and the tangential histories are carried over by pair, so
    the run is the same to the last bit."""
    config = RunConfig(edge_beads=4, impact="striker", strike_angle_deg=20.0, friction=friction, engine="reference")
    model = build_model(config)

    def run(name):
        samples = []
        engine = ReferenceEngine().run(
            model, run_settings(config, model), tmp_path / name, samples.append, show_progress=False
        )
        spins = [np.zeros(0) if s.angular_velocities is None else s.angular_velocities for s in samples]
        return engine, np.array([s.velocities for s in samples]), np.array(spins)

    usual = run("usual")
    monkeypatch.setattr(contacts, "skin_of", lambda diameters: 1e-5 * np.min(diameters))
    often = run("often")
    assert usual[0]["n_list_builds"] == 1 and often[0]["n_list_builds"] > 100
    np.testing.assert_array_equal(often[1], usual[1])
    np.testing.assert_array_equal(often[2], usual[2])
    assert friction == 0 or np.abs(usual[2]).max() > 0


def test_engines_agree_on_a_square_packing(tmp_path):
    """LAMMPS (every overlap, its own neighbour list) and the reference engine (its neighbour list)
    on a square packing struck obliquely at 20°, within the comparison's tolerances, on every bead:
    the pulse runs along the struck row (the strike's x part) and up the struck column (its y part)."""
    model, row = square(6, 8)
    model = GranularModel(model.packing, Impact(V0, angle_deg=20.0), STEEL_316, wall=None)
    settings = RunSettings(dt_s=TAU / 140, n_steps=8 * 140, dump_every=7, contact_time_s=TAU)
    tolerances = Tolerances().for_run(model, settings)
    lammps, reference = (
        ImpactAnalysis.from_trajectory(model, settings, record(engine, model, settings, tmp_path / engine.name)).results
        for engine in (LammpsEngine(), ReferenceEngine())
    )
    moving = np.nan_to_num(lammps.peak_speed) > tolerances.min_peak_fraction * V0
    column = np.arange(row[0], model.n_bodies, 8)
    np.testing.assert_array_equal(np.flatnonzero(moving), np.union1d(row, column))
    np.testing.assert_allclose(reference.peak_speed[moving], lammps.peak_speed[moving], rtol=tolerances.peak_rel)
    difference = np.abs(reference.arrival_time[moving] - lammps.arrival_time[moving])
    assert np.all(difference <= tolerances.arrival(lammps.arrival_time[moving])), difference.max()
