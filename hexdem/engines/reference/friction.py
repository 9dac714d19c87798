"""A frictional :class:`~hexdem.model.granular.GranularModel` laid out for
:mod:`hexdem.engines.reference.friction_kernel`: every contact in an explicit list with its law.

Each body is its own cell (no grid). The contacts are the lattice's bonds and the strikers' pairs
(as in the frictionless system) and the walls' members, each with the law of its materials
(:attr:`~hexdem.model.granular.GranularModel.laws`): A = k_n sqrt(R_eff), Tsuji's η = α sqrt(m_eff A),
K = k_t sqrt(R_eff), μ.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hexdem.engines.reference.contacts import coefficient, reduced, striker_bodies, wall_geometry
from hexdem.engines.reference.friction_kernel import FrictionArrays, frictional_forces, integrate_frictional
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.units import UnitSystem

#: Moment of inertia of a solid sphere, I = INERTIA m r² (LAMMPS's ``fix nve/sphere``).
INERTIA = 0.4


def _pair_arrays(model: GranularModel, units: UnitSystem):
    """The bead–bead and striker contacts (i → j): cells, rest vectors, c, A, η, K, μ and radii."""
    bonds = model.lattice.bonds()
    strikers, bodies = striker_bodies(model)
    i, j = np.concatenate([bonds[:, 0], strikers]), np.concatenate([bonds[:, 1], bodies])
    pos, radii = model.initial_positions_m() / units.length_m, model.diameters_m / 2
    ids, laws = model.material_ids, model.laws
    r_eff, masses = reduced(radii[i], radii[j]), model.masses_kg / units.mass_kg
    stiffness = coefficient(laws.pair_table("normal_stiffness_pa")[ids[i], ids[j]], r_eff, units)
    damping = laws.pair_table("damping")[ids[i], ids[j]] * np.sqrt(reduced(masses[i], masses[j]) * stiffness)
    tangential = coefficient(laws.pair_table("tangential_stiffness_pa")[ids[i], ids[j]], r_eff, units)
    rest = pos[j] - pos[i]
    return (i.astype(np.int64), j.astype(np.int64), rest[:, 0].copy(), rest[:, 1].copy(),
            (radii[i] + radii[j]) / units.length_m, stiffness, damping, tangential,
            laws.pair_table("friction")[ids[i], ids[j]], radii[i] / units.length_m, radii[j] / units.length_m)


def _wall_arrays(model: GranularModel, units: UnitSystem):
    """The bead–wall contacts: cells, inward normals, rest gaps, curvatures, A_w, η_w, K_w, μ_w, radii."""
    beads, normals, gaps, curvature, r_eff = wall_geometry(model)
    laws, ids = model.laws, model.material_ids[beads]

    def table(name):
        return laws.wall_table(name)[ids]

    stiffness = coefficient(table("normal_stiffness_pa"), r_eff, units)
    damping = table("damping") * np.sqrt(model.masses_kg[beads] / units.mass_kg * stiffness)
    return (beads.astype(np.int64), normals[:, 0].copy(), normals[:, 1].copy(), gaps / units.length_m,
            curvature * units.length_m, stiffness, damping, coefficient(table("tangential_stiffness_pa"), r_eff, units),
            table("friction"), model.lattice.radii_m[beads] / units.length_m)


@dataclass(frozen=True)
class FrictionalSystem:
    """A frictional model in ``units`` for the frictional kernel; ``state`` holds the spins ω and
    the contacts' histories ξ of the integration under way (empty before it)."""

    kernel: FrictionArrays
    cells: np.ndarray
    n_cells: int
    units: UnitSystem
    state: dict = field(default_factory=dict, compare=False)

    @classmethod
    def from_model(cls, model: GranularModel, units: UnitSystem) -> "FrictionalSystem":
        n = model.n_bodies
        masses = model.masses_kg / units.mass_kg
        radii = model.diameters_m / 2 / units.length_m
        external = model.external_forces_n() / units.force_n
        kernel = FrictionArrays(*_pair_arrays(model, units), *_wall_arrays(model, units), 1.0 / masses,
                                1.0 / (INERTIA * masses * radii**2), external[:, 0].copy(), external[:, 1].copy())
        return cls(kernel, np.arange(n, dtype=np.int64), n, units)

    @property
    def n_bonds(self) -> int:
        return len(self.kernel.pair_i)

    @property
    def n_wall_contacts(self) -> int:
        return len(self.kernel.wall_cell)

    def angular_velocities(self) -> np.ndarray:
        """(n_bodies,) the spins ω_z of the integration under way, in ``units``."""
        return self.state["spins"].copy()

    def accelerations(self, x, y, u, w) -> np.ndarray:
        """(n_bodies, 2) accelerations at the displacements (x, y) and velocities (u, w), with the
        spins and histories of the integration under way."""
        k, n = self.kernel, self.n_cells
        fx, fy, torque = np.zeros(n), np.zeros(n), np.zeros(n)
        pair_xi, wall_xi = self.state["pair_xi"].copy(), self.state["wall_xi"].copy()
        frictional_forces(k, x, y, u, w, self.state["spins"], pair_xi, wall_xi, False, fx, fy, torque,
                          np.zeros(len(pair_xi)), np.zeros(len(wall_xi)))
        return np.column_stack([fx * k.inv_mass, fy * k.inv_mass])

    def integrate(self, velocities, dt: float, settings: RunSettings, emit):
        """RK4 from rest positions with ``velocities`` and no spin (in ``units``);
        ``emit(index, step, x, y, u, w)`` at step 0 and every ``settings.dump_every`` steps, the spins
        in ``state["spins"]`` meanwhile."""
        n = self.n_cells
        x, y = np.zeros(n), np.zeros(n)
        u, w = (np.array(column, float) for column in np.asarray(velocities, float).T)
        self.state.update(spins=np.zeros(n),
                          pair_xi=np.zeros(self.n_bonds), wall_xi=np.zeros(self.n_wall_contacts))
        every = settings.dump_every
        emit(0, 0, x, y, u, w)
        for index in range(1, settings.n_samples):
            integrate_frictional(self.kernel, x, y, u, w, self.state["spins"], self.state["pair_xi"],
                                 self.state["wall_xi"], float(dt), every)
            emit(index, index * every, x, y, u, w)
