"""Analysis of LAMMPS dumps with MDAnalysis, in the shape of MDAnalysis's own analyses.

:func:`open_dump` reads a hexdem dump (``id type x y z vx vy vz dx dy``, where dx, dy are the
full-precision displacements from ``compute displace/atom``). :class:`BeadRecord` walks its
frames once (``run()`` → ``results``) and keeps each body's speed and, for the energy audit,
its position rebuilt as exact initial position + displacement. MDAnalysis stores positions
and velocities as float32 (≈2e-8 m here, too coarse for Hertz overlaps of ~1e-5 m, and
short of the 1e-9 agreement between rank counts), so velocities and displacements are read
as additional columns, at full double precision.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from hexdem.analysis.trajectory import Trajectory
from hexdem.errors import HexdemError
from hexdem.model.granular import RunSettings

#: Columns read at full precision (MDAnalysis's own positions and velocities are float32).
FULL_PRECISION_COLUMNS = ("vx", "vy", "dx", "dy")


def open_dump(path, dt: float):
    """An MDAnalysis Universe over a hexdem dump; ``dt`` is the MD time step (run units)."""
    import MDAnalysis as mda

    path = Path(path)
    if not path.is_file():
        raise HexdemError(f"dump file {path} does not exist")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return mda.Universe(str(path), format="LAMMPSDUMP", dt=dt, additional_columns=list(FULL_PRECISION_COLUMNS))
    except Exception as exc:
        raise HexdemError(
            f"cannot read dump {path}: it is corrupt or not a hexdem dump "
            f"({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else 'no detail'})"
        ) from None


def _analysis_base():
    from MDAnalysis.analysis.base import AnalysisBase

    return AnalysisBase


class BeadRecord(_analysis_base()):
    """Per-frame speeds and displacements of every body in a hexdem dump.

    ``results.times`` (n_frames,) in the dump's units; ``results.speeds`` (n_frames, n_atoms)
    the speed in the plane; ``results.velocities`` and ``results.displacements`` (n_frames,
    n_atoms, 2). Atoms are ordered by id (hexdem dumps are sorted by id).
    """

    def __init__(self, universe, **kwargs):
        super().__init__(universe.trajectory, **kwargs)
        self._n_atoms = universe.atoms.n_atoms

    def _prepare(self):
        shape = (self.n_frames, self._n_atoms, 2)
        self.results.times = np.zeros(self.n_frames)
        self.results.velocities = np.zeros(shape)
        self.results.displacements = np.zeros(shape)

    def _single_frame(self):
        ts = self._ts
        missing = [name for name in FULL_PRECISION_COLUMNS if name not in ts.data]
        if missing:
            raise HexdemError(f"frame {ts.frame} of the dump lacks the column(s) {', '.join(missing)}")
        frame = self._frame_index
        self.results.times[frame] = ts.time
        self.results.velocities[frame] = np.column_stack([ts.data["vx"], ts.data["vy"]])
        self.results.displacements[frame] = np.column_stack([ts.data["dx"], ts.data["dy"]])

    def _conclude(self):
        self.results.speeds = np.linalg.norm(self.results.velocities, axis=2)


def read_dump(path, dt: float, expected_frames: int | None = None) -> BeadRecord:
    """Open and walk a hexdem dump: the finished :class:`BeadRecord`.

    MDAnalysis silently drops an incomplete last frame, so a dump cut short (a killed or
    crashed run) is only recognised by its frame count: pass ``expected_frames``.
    """
    universe = open_dump(path, dt)
    if expected_frames is not None and len(universe.trajectory) != expected_frames:
        raise HexdemError(
            f"dump {path} is corrupt or truncated: {len(universe.trajectory)} of {expected_frames} frames"
        )
    try:
        return BeadRecord(universe).run(verbose=sys.stderr.isatty())
    except HexdemError:
        raise
    except Exception as exc:
        raise HexdemError(f"cannot read dump {path}: it is corrupt or truncated ({type(exc).__name__})") from None


def read_trajectory(path, settings: RunSettings, engine: dict | None = None) -> Trajectory:
    """The hexdem dump at ``path`` of a run with ``settings`` (all its frames required) as a SI
    :class:`~hexdem.analysis.trajectory.Trajectory`; ``engine`` describes the run."""
    units = settings.units
    record = read_dump(path, settings.dt_s / units.time_s, settings.n_samples).results
    return Trajectory(
        times_s=record.times * units.time_s,
        velocities_m_s=record.velocities * units.velocity_m_s,
        displacements_m=record.displacements * units.length_m,
        engine=engine or {},
    )
