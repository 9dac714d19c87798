"""hexdem: impulses in 2D hexagonal granular crystals, driven through LAMMPS.

Reproduces and extends Leonard, Chong, Kevrekidis & Daraio, "Traveling Waves in 2D
Hexagonal Granular Crystal Lattices". The subpackages follow the data flow:
:mod:`hexdem.model` (lattice, materials, units, Hertz law, configuration) →
:mod:`hexdem.engines` (LAMMPS and the RK4 reference integrator, streaming samples) →
:mod:`hexdem.analysis` (the tracker inside the run, peaks, arrival, energy, dumps, figures) →
:mod:`hexdem.experiments` (one run, the engine cross-check, snapshots) →
:mod:`hexdem.theory` (TCA, scaling laws) and :mod:`hexdem.disorder` (Sec. VI ensembles) →
:mod:`hexdem.cli`. :mod:`hexdem.common` holds helpers every layer uses.

The Python API (:mod:`hexdem.api`) is available here and imported on first use, so that
``import hexdem`` stays light: ``hexdem.RunConfig``, ``hexdem.simulate_impact``,
``hexdem.tca``, ``hexdem.SweepSettings``, ``hexdem.scaling_laws``, ``hexdem.calibrate`` and its
``hexdem.Posterior``.
"""

import os

#: One BLAS thread. hexdem's linear algebra is small (fits of a few parameters, barycentric
#: transforms of a few hundred triangles), and OpenBLAS's pool of spinning threads slows it many
#: times over whenever another process, a LAMMPS rank for one, holds the other core
#: (docs/validation/benchmarks.md, *Figures behind choices in the code*).
#: Set here, before NumPy loads its BLAS; a value the user set is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from hexdem.api_names import API_NAMES as _API  # noqa: E402
from hexdem.errors import HexdemError  # noqa: E402

__all__ = ["HexdemError", *_API]


def __getattr__(name):
    if name in _API:
        from hexdem import api

        return getattr(api, name)
    raise AttributeError(f"module 'hexdem' has no attribute {name!r}")
