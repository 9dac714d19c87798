"""A frictional :class:`~hexdem.model.granular.GranularModel` laid out for
:mod:`hexdem.engines.reference.friction_kernel`: every contact in an explicit list with its law.

The contacts are the pairs of the neighbour list, beads and strikers alike (as in the frictionless
system, rebuilt as the bodies move), and the walls' members, each with the law of its materials
(:attr:`~hexdem.model.granular.GranularModel.laws`): A = k_n sqrt(R_eff), Tsuji's η = α sqrt(m_eff A),
K = k_t sqrt(R_eff), μ. A rebuild carries every listed pair's tangential history ξ over by its
(i, j) key (:func:`~hexdem.engines.reference.neighbours.carried_over`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hexdem.engines.reference.contacts import ListedPairs, PairLaws, coefficient, wall_geometry
from hexdem.engines.reference.friction_kernel import FrictionArrays, frictional_forces, integrate_frictional
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.units import UnitSystem

#: Moment of inertia of a solid sphere, I = INERTIA m r² (LAMMPS's ``fix nve/sphere``).
INERTIA = 0.4


def _pair_fields(laws: PairLaws):
    """The kernel's per-pair fields of pairs (i → j): rest vectors, c, A, η, K, μ and radii."""

    def fields(i, j) -> dict:
        rest_x, rest_y, contact, stiffness, damping = laws.normal(i, j)
        tangential, mu, radius_i, radius_j = laws.tangential(i, j)
        return dict(
            pair_rest_x=rest_x,
            pair_rest_y=rest_y,
            pair_contact=contact,
            pair_stiffness=stiffness,
            pair_damping=damping,
            pair_tangential=tangential,
            pair_mu=mu,
            pair_radius_i=radius_i,
            pair_radius_j=radius_j,
        )

    return fields


def _wall_fields(model: GranularModel, units: UnitSystem) -> dict:
    """The kernel's wall fields: bodies, inward normals, rest gaps, curvatures, A_w, η_w, K_w, μ_w, radii."""
    beads, normals, gaps, curvature, r_eff = wall_geometry(model)
    laws, ids = model.laws, model.material_ids[beads]

    def table(name):
        return laws.wall_table(name)[ids]

    stiffness = coefficient(table("normal_stiffness_pa"), r_eff, units)
    damping = table("damping") * np.sqrt(model.masses_kg[beads] / units.mass_kg * stiffness)
    return dict(
        wall_cell=beads.astype(np.int64),
        wall_nx=normals[:, 0].copy(),
        wall_ny=normals[:, 1].copy(),
        wall_gap=gaps / units.length_m,
        wall_curvature=curvature * units.length_m,
        wall_stiffness=stiffness,
        wall_damping=damping,
        wall_tangential=coefficient(table("tangential_stiffness_pa"), r_eff, units),
        wall_mu=table("friction"),
        wall_radius=model.packing.radii_m[beads] / units.length_m,
    )


@dataclass
class FrictionalSystem:
    """A frictional model in ``units`` for the frictional kernel: its walls and the pairs of its
    neighbour list (``pairs``, rebuilt during the integration); ``state`` holds the spins ω and the
    wall contacts' histories ξ of the integration under way (empty before it), ``pairs.carried`` the
    listed pairs' histories ξ (``"pair_xi"``)."""

    pairs: ListedPairs
    units: UnitSystem
    state: dict = field(default_factory=dict, compare=False)

    @classmethod
    def from_model(cls, model: GranularModel, units: UnitSystem) -> FrictionalSystem:
        laws = PairLaws.of(model, units)
        masses, radii = laws.masses, laws.radii
        external = model.external_forces_n() / units.force_n
        body = dict(
            **_wall_fields(model, units),
            inv_mass=1.0 / masses,
            inv_inertia=1.0 / (INERTIA * masses * radii**2),
            external_x=external[:, 0].copy(),
            external_y=external[:, 1].copy(),
        )
        return cls(
            ListedPairs.at_rest(laws, _pair_fields(laws), lambda **listed: FrictionArrays(**listed, **body)), units
        )

    @property
    def kernel(self) -> FrictionArrays:
        return self.pairs.kernel

    @property
    def n_wall_contacts(self) -> int:
        return len(self.kernel.wall_cell)

    def angular_velocities(self) -> np.ndarray:
        """(n_bodies,) the spins ω_z of the integration under way, in ``units``."""
        return self.state["spins"].copy()

    def accelerations(self, x, y, u, w) -> np.ndarray:
        """(n_bodies, 2) accelerations at the displacements (x, y) and velocities (u, w), with the
        spins and histories of the integration under way."""
        k, n = self.kernel, len(x)
        fx, fy, torque = np.zeros(n), np.zeros(n), np.zeros(n)
        pair_xi, wall_xi = self.pairs.carried["pair_xi"].copy(), self.state["wall_xi"].copy()
        frictional_forces(
            k,
            x,
            y,
            u,
            w,
            self.state["spins"],
            pair_xi,
            wall_xi,
            False,
            fx,
            fy,
            torque,
            np.zeros(len(pair_xi)),
            np.zeros(len(wall_xi)),
        )
        return np.column_stack([fx * k.inv_mass, fy * k.inv_mass])

    def integrate(self, velocities, dt: float, settings: RunSettings, emit):
        """RK4 from rest positions with ``velocities`` and no spin (in ``units``);
        ``emit(index, step, x, y, u, w)`` at step 0 and every ``settings.dump_every`` steps, the spins
        in ``state["spins"]`` meanwhile."""
        n = len(velocities)
        x, y = np.zeros(n), np.zeros(n)
        u, w = (np.array(column, float) for column in np.asarray(velocities, float).T)
        self.state.update(spins=np.zeros(n), wall_xi=np.zeros(self.n_wall_contacts))
        self.pairs.carried["pair_xi"] = np.zeros(self.pairs.n_pairs)
        every = settings.dump_every
        emit(0, 0, x, y, u, w)

        def steps(kernel, n_steps):
            return integrate_frictional(
                kernel,
                x,
                y,
                u,
                w,
                self.state["spins"],
                self.pairs.carried["pair_xi"],
                self.state["wall_xi"],
                float(dt),
                n_steps,
            )

        for index in range(1, settings.n_samples):
            self.pairs.advance(every, steps, x, y)
            emit(index, index * every, x, y, u, w)
