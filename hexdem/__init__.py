"""hexdem: impulses in 2D hexagonal granular crystals, driven through LAMMPS.

Reproduces and extends Leonard, Chong, Kevrekidis & Daraio, "Traveling Waves in 2D
Hexagonal Granular Crystal Lattices". Data flow: geometry (:mod:`hexdem.lattice`) →
model (:mod:`hexdem.model`) → engine (LAMMPS, :mod:`hexdem.lammps`, or the RK4 reference
integrator, :mod:`hexdem.reference`) → :class:`~hexdem.trajectory.Trajectory` → analysis
(:mod:`hexdem.impact`, :mod:`hexdem.peaks`) → figures (:mod:`hexdem.plots`). Theory lives in
:mod:`hexdem.tca` and :mod:`hexdem.scaling`; weak disorder in :mod:`hexdem.disorder`,
:mod:`hexdem.ensemble` and :mod:`hexdem.ensemble_stats`.
"""

from hexdem.errors import HexdemError

__all__ = ["HexdemError"]
