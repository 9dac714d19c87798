"""hexdem: impulses in 2D hexagonal granular crystals, driven through LAMMPS.

Reproduces and extends Leonard, Chong, Kevrekidis & Daraio, "Traveling Waves in 2D
Hexagonal Granular Crystal Lattices". Data flow: geometry (:mod:`hexdem.model.lattice`) →
model (:mod:`hexdem.model.granular`) → engine (LAMMPS, :mod:`hexdem.engines.lammps`, or the RK4 reference
integrator, :mod:`hexdem.engines.reference.engine`) → :class:`~hexdem.analysis.trajectory.Trajectory` → analysis
(:mod:`hexdem.analysis.impact`, :mod:`hexdem.analysis.peaks`) → figures (:mod:`hexdem.analysis.figures`). Theory lives in
:mod:`hexdem.theory.tca` and :mod:`hexdem.theory.scaling`; weak disorder in :mod:`hexdem.disorder.preparation`,
:mod:`hexdem.disorder.ensemble` and :mod:`hexdem.disorder.stats`.
"""

from hexdem.errors import HexdemError

__all__ = ["HexdemError"]
