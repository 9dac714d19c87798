"""hexdem: impulses in 2D hexagonal granular crystals, driven through LAMMPS.

Reproduces and extends Leonard, Chong, Kevrekidis & Daraio, "Traveling Waves in 2D
Hexagonal Granular Crystal Lattices". Data flow: geometry (:mod:`hexdem.lattice`) →
model (:mod:`hexdem.model`) → engine (:mod:`hexdem.lammps`) → trajectory → analysis
(:mod:`hexdem.impact`, :mod:`hexdem.peaks`) → figures (:mod:`hexdem.plots`).
"""

from hexdem.errors import HexdemError

__all__ = ["HexdemError"]
