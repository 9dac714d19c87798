"""Elastic decks use ``pair_style gran/hertz/history`` (faster); damped ones ``pair_style granular``.

The two must give the same forces: on a compressed, disordered packing pressed into its walls
and struck, every bead's force and torque after each of 200 steps is compared between the deck
hexdem writes and the same deck with the pair lines of ``pair_style granular hertz``.
"""

from dataclasses import replace

import numpy as np

from hexdem.engines.lammps.deck import DECK_NAME, pair_block, write_deck
from hexdem.engines.lammps.library import load_lammps
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings
from hexdem.model.units import SI

GRANULAR_PAIR = (
    "pair_style      granular\n"
    "pair_coeff      * * hertz {k} 0.0 damping viscoelastic tangential linear_nohistory 0.0 0.0"
)


def compressed_model():
    """The 4-per-edge experiment with diameters 0-0.1 % too large for their sites: every bead
    overlaps its neighbours and the edge beads overlap their walls (by up to 4.8 µm)."""
    model = build_model(RunConfig(edge_beads=4, impact="striker"))
    lattice = model.packing
    grown = lattice.diameters_m * (1 + 1e-3 * np.random.default_rng(7).random(len(lattice)))
    return replace(model, packing=replace(lattice, diameters_m=grown))


def forces_every_step(directory, pair_lines: str | None, steps: int):
    """(steps + 1, N, 2) forces and (steps + 1, N) z torques of the deck in ``directory``, its
    pair lines replaced by ``pair_lines`` if given."""
    text = (directory / DECK_NAME).read_text()
    setup = text[: text.index("# --- output")]
    if pair_lines is not None:
        start = setup.index("pair_style")
        end = setup.index("\n", setup.index("pair_coeff"))
        setup = setup[:start] + pair_lines + setup[end:]
    lmp = load_lammps().lammps(cmdargs=["-log", "none", "-screen", "none"])
    forces, torques = [], []
    try:
        lmp.command(f'shell cd "{directory}"')
        lmp.commands_string(setup)
        for step in range(steps + 1):
            lmp.command("run 1 pre no post no" if step else "run 0")
            order = np.argsort(lmp.numpy.extract_atom("id"))
            forces.append(np.array(lmp.numpy.extract_atom("f"))[order, :2])
            torques.append(np.array(lmp.numpy.extract_atom("torque"))[order, 2])
    finally:
        lmp.close()
    return np.array(forces), np.array(torques)


def test_elastic_decks_use_gran_hertz_history_and_damped_ones_granular():
    model = compressed_model()
    assert pair_block(model, SI).startswith("pair_style      gran/hertz/history")
    assert "damping tsuji" in pair_block(replace(model, restitution=0.9), SI)


def test_gran_hertz_history_forces_equal_granular_hertz_walls_included(tmp_path):
    model = compressed_model()
    settings = run_settings(RunConfig(edge_beads=4, impact="striker"), model)
    k = pair_block(model, SI).split()[2]
    history = write_deck(model, settings, tmp_path / "history").directory
    granular = write_deck(model, settings, tmp_path / "granular").directory
    f_history, t_history = forces_every_step(history, None, 200)
    f_granular, t_granular = forces_every_step(granular, GRANULAR_PAIR.format(k=k), 200)
    scale = np.abs(f_granular).max()
    assert scale > 1.0  # overlaps of micrometres: newtons
    walled = np.unique(np.concatenate([wall.members for wall in model.packing.walls]))
    assert np.abs(f_granular[0, walled]).max() > 0.1 * scale  # the walls push
    np.testing.assert_allclose(f_history, f_granular, rtol=0, atol=1e-12 * scale)
    assert np.all(t_history == 0.0) and np.all(t_granular == 0.0)  # no tangential force in either
