"""Reference integrator of the paper's Hamiltonian (Sec. III): an engine independent of LAMMPS.

It integrates eq. (model) as the paper does, with classical 4th-order Runge–Kutta:

* fixed bonds between the six touching neighbours of the lattice (``Lattice.bonds()``,
  the paper's e₁, e₂, e₃), each with V(r) = (2/5) A [c − r]_+^{5/2}: no tension, and a
  per-pair contact distance c = R_i + R_j and A = k_n sqrt(R_eff), so per-bead diameters
  work (for equal beads c = d and A is the paper's A);
* the Hertz force along the *current* line of centres, r = |rest + q_j − q_i|;
* flat walls as sphere–half-plane Hertz contacts with the wall's own modulus
  (F = k_n,wall sqrt(R) δ^{3/2}, the paper's "spheres with an infinite radius"), acting on
  the wall's member beads only, so the struck bead sits in the impact hole as in the decks;
* each impact's V0 on its bead, or on a striker sphere bonded to it (``Impact.striker``).

It works in the run's unit system (SI, or the paper's A = d = M = 1 of eq. (scaling)) and
hands its samples, taken like a LAMMPS dump's, to the same observer as LAMMPS, so the same
analysis judges both engines. Unlike LAMMPS, which
treats every overlapping pair as a contact, bonds are fixed; in a lattice whose
next-nearest neighbours never touch (all hexdem packings) the two coincide.

The force and RK4 loops are compiled (:mod:`hexdem.engines.reference.kernel`, numba). A model whose
contact law has a tangential force (friction) runs instead on the frictional kernel, with spins and
contact histories (:mod:`hexdem.engines.reference.friction`); the engine picks the kernel from the law.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path

import numpy as np

from hexdem.common.checks import is_number, positive_int
from hexdem.common.io import write_json
from hexdem.common.progress import progress_bar
from hexdem.engines.reference.contacts import coefficient, reduced, striker_bodies, wall_geometry
from hexdem.engines.reference.friction import FrictionalSystem
from hexdem.engines.reference.kernel import KernelArrays, forces, integrate
from hexdem.engines.sampling import Sample
from hexdem.errors import HexdemError
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.lattice import BOND_STEPS, Lattice
from hexdem.model.units import UnitSystem

#: Description of the run written into the engine's directory.
PARAMETERS_NAME = "reference.json"


@dataclass(frozen=True)
class Grid:
    """Padded (rows × cols) cell grid of a lattice: bead {m, n} → row n + 1, col (m + n)/2 + 1.

    ``cells`` (n_beads,) flat cell of each bead; ``cols`` C; ``n_cells`` rows · cols.
    """

    cells: np.ndarray
    cols: int
    n_cells: int

    @classmethod
    def of(cls, lattice: Lattice) -> "Grid":
        m, n = lattice.indices.T
        if np.any((m + n) % 2):
            raise HexdemError("lattice labels {m, n} must have m + n even (hexagonal packing indices)")
        row, col = n - n.min() + 1, (m + n) // 2
        col = col - col.min() + 1
        cols = int(col.max()) + 2
        return cls(cells=row * cols + col, cols=cols, n_cells=(int(row.max()) + 2) * cols)

    def offset(self, step) -> int:
        """Cell offset of the bond step (dm, dn) of :data:`~hexdem.model.lattice.BOND_STEPS`."""
        dm, dn = step
        return dn * self.cols + (dm + dn) // 2

    @property
    def lo(self) -> int:
        """First cell that can hold a bead (after the padding row and column)."""
        return self.cols + 1

    @property
    def hi(self) -> int:
        """One past the last cell that can start a bond (before the padding row)."""
        return self.n_cells - self.cols - 1


def _lattice_bonds(model: GranularModel, grid: Grid, units: UnitSystem):
    """(rest_x, rest_y, contact, stiffness, damping), each (3, hi), of the lattice's fixed bonds,
    their rest vectors those of the beads' positions at t = 0 (displacements q are from there)."""
    lattice = model.lattice
    shape = (len(BOND_STEPS), grid.hi)
    # Empty slots keep a rest vector of bond length, so r > 0 and their force is exactly 0.
    ideal = np.array([[math.sqrt(3) / 2 * dn, dm / 2] for dm, dn in BOND_STEPS]) * lattice.diameter_m / units.length_m
    rest_x, rest_y = np.repeat(ideal[:, :1], grid.hi, axis=1), np.repeat(ideal[:, 1:], grid.hi, axis=1)
    contact, stiffness, damping = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    i, j = lattice.bonds().T
    direction = {grid.offset(step): d for d, step in enumerate(BOND_STEPS)}
    d = np.array([direction[o] for o in grid.cells[j] - grid.cells[i]], dtype=int)
    cell, radii, start = grid.cells[i], lattice.radii_m, model.initial_positions_m()
    rest_x[d, cell], rest_y[d, cell] = (start[j] - start[i]).T / units.length_m
    contact[d, cell] = (radii[i] + radii[j]) / units.length_m
    stiffness[d, cell] = coefficient(model.contact_stiffness_pa(i, j), reduced(radii[i], radii[j]), units)
    masses = model.masses_kg / units.mass_kg
    damping[d, cell] = model.pair_damping * np.sqrt(reduced(masses[i], masses[j]) * stiffness[d, cell])
    return rest_x, rest_y, contact, stiffness, damping


def _striker_pairs(model: GranularModel, cells: np.ndarray, units: UnitSystem):
    """Bonds of each striker to the bodies within its reach (:func:`~hexdem.engines.reference.contacts.striker_bodies`)."""
    pos, radii = model.initial_positions_m(), model.diameters_m / 2
    strikers, bodies = striker_bodies(model)
    rest = (pos[bodies] - pos[strikers]) / units.length_m
    r_eff = reduced(radii[bodies], radii[strikers])
    stiffness = coefficient(model.contact_stiffness_pa(bodies, strikers), r_eff, units)
    masses = model.masses_kg / units.mass_kg
    damping = model.pair_damping * np.sqrt(reduced(masses[bodies], masses[strikers]) * stiffness)
    return (cells[strikers].astype(np.int64), cells[bodies].astype(np.int64), rest[:, 0].copy(), rest[:, 1].copy(),
            (radii[bodies] + radii[strikers]) / units.length_m, stiffness, damping)


def _wall_contacts(model: GranularModel, cells: np.ndarray, units: UnitSystem):
    """(cell, n_x, n_y, rest gap, curvature, A_w, η_w) of every wall member: sphere–wall Hertz
    (:func:`~hexdem.engines.reference.contacts.wall_geometry`), A_w = k_n,wall sqrt(R_eff)."""
    beads, normals, gaps, curvature, r_eff = wall_geometry(model)
    stiffness = coefficient(model.wall_stiffness_pa(beads) if model.walls else np.zeros(0), r_eff, units)
    damping = model.wall_damping * np.sqrt(model.masses_kg[beads] / units.mass_kg * stiffness)
    return (cells[beads], normals[:, 0].copy(), normals[:, 1].copy(), gaps / units.length_m,
            curvature * units.length_m, stiffness, damping)


def _cell_forces(forces, cells: np.ndarray, n_cells: int):
    """(fx, fy) over all cells of per-body ``forces`` (n_bodies, 2)."""
    grid = np.zeros((2, n_cells))
    grid[:, cells] = np.asarray(forces, float).T
    return grid[0], grid[1]


@dataclass(frozen=True)
class ReferenceSystem:
    """A :class:`GranularModel` in ``units``, laid out for :mod:`hexdem.engines.reference.kernel`.

    ``kernel`` the arrays of eq. (model); ``cells`` (n_bodies,) the cell of each body
    (beads, then the striker); ``n_cells`` grid cells plus off-grid bodies.
    """

    kernel: KernelArrays
    cells: np.ndarray
    n_cells: int
    units: UnitSystem

    @classmethod
    def from_model(cls, model: GranularModel, units: UnitSystem) -> "ReferenceSystem":
        grid = Grid.of(model.lattice)
        off_grid = model.n_bodies - len(model.lattice)
        cells = np.concatenate([grid.cells, grid.n_cells + np.arange(off_grid)]).astype(np.int64)
        n_cells = grid.n_cells + off_grid
        inv_mass = np.zeros(n_cells)
        inv_mass[cells] = units.mass_kg / model.masses_kg
        rest_x, rest_y, contact, stiffness, damping = _lattice_bonds(model, grid, units)
        *pairs, pair_damping = _striker_pairs(model, cells, units)
        *walls, wall_damping = _wall_contacts(model, cells, units)
        kernel = KernelArrays(np.array([grid.offset(step) for step in BOND_STEPS], dtype=np.int64),
                              grid.lo, grid.hi, rest_x, rest_y, contact, stiffness, inv_mass, *pairs, *walls,
                              damping, pair_damping, wall_damping, model.dissipative,
                              *_cell_forces(model.external_forces_n() / units.force_n, cells, n_cells))
        return cls(kernel, cells, n_cells, units)

    @property
    def n_bonds(self) -> int:
        return int(np.count_nonzero(self.kernel.stiffness)) + len(self.kernel.pair_i)

    @property
    def n_wall_contacts(self) -> int:
        return len(self.kernel.wall_cell)

    def angular_velocities(self) -> None:
        """The bodies' spins: none, frictionless spheres never turn."""
        return None

    def _cell_arrays(self, values):
        """(n_bodies, 2) body values → x and y arrays over all cells."""
        return _cell_forces(values, self.cells, self.n_cells)

    def forces(self, displacements) -> np.ndarray:
        """(n_bodies, 2) net Hertz force on every body at ``displacements``, at rest (both in ``units``)."""
        x, y = self._cell_arrays(displacements)
        fx, fy = np.zeros(self.n_cells), np.zeros(self.n_cells)
        scratch = np.zeros((2, 3, self.kernel.hi))
        still = np.zeros(self.n_cells)
        forces(self.kernel, x, y, still, still, np.ones(self.n_cells), scratch[0], scratch[1], fx, fy)
        return np.column_stack([fx[self.cells], fy[self.cells]])

    def accelerations(self, x, y, u, w) -> np.ndarray:
        """(n_bodies, 2) accelerations at the cell displacements (x, y) and velocities (u, w)."""
        ax, ay = np.zeros(self.n_cells), np.zeros(self.n_cells)
        scratch = np.zeros((2, 3, self.kernel.hi))
        forces(self.kernel, x, y, u, w, self.kernel.inv_mass, scratch[0], scratch[1], ax, ay)
        return np.column_stack([ax[self.cells], ay[self.cells]])

    def integrate(self, velocities, dt: float, settings: RunSettings, emit):
        """RK4 from rest positions with ``velocities`` (in ``units``); ``emit(index, step, x, y, u, w)``
        at step 0 and every ``settings.dump_every`` steps, with the cell arrays of
        displacements (x, y) and velocities (u, w)."""
        x, y = self._cell_arrays(np.zeros_like(velocities))
        u, w = self._cell_arrays(velocities)
        every = settings.dump_every
        emit(0, 0, x, y, u, w)
        for index in range(1, settings.n_samples):
            integrate(self.kernel, x, y, u, w, float(dt), every)
            emit(index, index * every, x, y, u, w)


def _check_settings(settings: RunSettings) -> None:
    if not (is_number(settings.dt_s) and settings.dt_s > 0):
        raise HexdemError(f"time step must be a positive number of seconds, got {settings.dt_s!r}")
    for name in ("n_steps", "dump_every"):
        positive_int(name, getattr(settings, name))


@dataclass(frozen=True)
class ReferenceEngine:
    """The reference integrator as a hexdem engine (same protocol as ``LammpsEngine``; one rank)."""

    name = "reference"

    def run(self, model: GranularModel, settings: RunSettings, directory, on_sample, comm=None,
            show_progress: bool = True) -> dict:
        """Integrate ``model`` with ``settings``, calling ``on_sample`` with every sample; write
        ``reference.json`` into ``directory``. Returns a description of the run."""
        _check_settings(settings)
        if comm is not None and comm.Get_size() > 1:
            raise HexdemError("the reference integrator runs on one rank; use ranks = 1 with it")
        units = settings.units
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        system = (FrictionalSystem if model.laws.tangential else ReferenceSystem).from_model(model, units)
        start_positions = model.initial_positions_m() / units.length_m
        ids = np.arange(1, model.n_bodies + 1)
        dt = settings.dt_s / units.time_s
        bar = progress_bar(settings.n_steps, "reference", unit="step") if show_progress else None

        def emit(index, step, x, y, u, w):
            cells = system.cells
            velocities = np.column_stack([u[cells], w[cells]])
            sensed = settings.sensor_every and step % settings.sensor_every == 0
            accelerations = system.accelerations(x, y, u, w) if sensed else None
            if not np.isfinite(velocities).all():
                raise HexdemError(f"reference integration diverged (non-finite velocities at t = "
                                  f"{step * settings.dt_s:.4g} s): reduce the time step")
            on_sample(Sample(index, step, step * dt, ids, start_positions + np.column_stack([x[cells], y[cells]]),
                             velocities, accelerations, system.angular_velocities()))
            if bar is not None:
                bar.update(step - bar.n)

        begin = time.perf_counter()
        try:
            system.integrate(model.initial_velocities_m_s() / units.velocity_m_s, dt, settings, emit)
        finally:
            if bar is not None:
                bar.close()
        engine = {"name": self.name, "version": version("hexdem"), "ranks": 1, "integrator": "classical RK4",
                  "friction": model.laws.tangential,
                  "units": units.name, "wall_time_s": time.perf_counter() - begin, "n_bonds": system.n_bonds,
                  "n_wall_contacts": system.n_wall_contacts}
        write_json(directory / PARAMETERS_NAME, {**engine, "model": model.lattice.shape, "n_bodies": model.n_bodies,
                                                 "time_step": dt, "n_steps": settings.n_steps,
                                                 "dump_every": settings.dump_every,
                                                 "unit_scales_si": {"length_m": units.length_m,
                                                                    "mass_kg": units.mass_kg,
                                                                    "time_s": units.time_s}})
        return engine
