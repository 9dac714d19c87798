r"""The prestress a prepared packing keeps: the Hertz forces of its contacts and on its walls.

Sec. VI-A places the walls touching the packing while 5 N forces still compact it, then
removes the forces: the packing springs back against the walls and keeps part of its
compression. That static load is not in the paper's ideal lattice, which is struck
uncompressed, so it is measured here for every settled packing.

Forces are LAMMPS's ``hertz`` law, :math:`F = k_n \sqrt{R_\text{eff}}\, δ^{3/2}` with the model's k_n: bead
pairs with R_eff = r_i r_j / (r_i + r_j), bead–wall contacts with the bead's radius and the
wall's own E, ν (:class:`~hexdem.model.granular.GranularModel`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.model.granular import GranularModel

#: Per-realization arrays of ``result.npz`` that describe the prestress (see :class:`Prestress`).
PRESTRESS_ARRAYS = ("mean_contact_force_n", "max_contact_force_n", "wall_force_n")


#: Overlaps below this fraction of the largest radius are round-off of beads that just touch.
ROUND_OFF = 1e-10


def touching_pairs(positions_m, diameters_m):
    """(i, j, overlap δ [m]) of every pair of beads that overlap by more than round-off."""
    from scipy.spatial import cKDTree  # here: an impact's process imports this module and need not load scipy

    positions_m, radii = np.asarray(positions_m, float), np.asarray(diameters_m, float) / 2
    pairs = cKDTree(positions_m).query_pairs(2 * radii.max(), output_type="ndarray")
    i, j = pairs.T
    overlap = radii[i] + radii[j] - np.linalg.norm(positions_m[i] - positions_m[j], axis=1)
    touching = overlap > ROUND_OFF * radii.max()
    return i[touching], j[touching], overlap[touching]


@dataclass(frozen=True)
class Prestress:
    """Static load of a packing at rest: ``contacts`` touching bead pairs, their largest
    overlap ``max_overlap_m`` [m], ``mean_contact_force_n`` and ``max_contact_force_n`` [N]
    (0 without contacts), and ``wall_force_n``, the sum of the normal forces the walls exert [N]."""

    contacts: int
    max_overlap_m: float
    mean_contact_force_n: float
    max_contact_force_n: float
    wall_force_n: float

    def as_arrays(self) -> dict:
        return {name: float(getattr(self, name)) for name in PRESTRESS_ARRAYS}


def prestress(model: GranularModel) -> Prestress:
    """The contact and wall forces of ``model``'s packing as it stands (the striker excluded)."""
    lattice = model.packing
    radii = lattice.diameters_m / 2
    i, j, overlap = touching_pairs(lattice.positions_m, lattice.diameters_m)
    reduced = radii[i] * radii[j] / (radii[i] + radii[j])
    forces = model.contact_stiffness_pa(i, j) * np.sqrt(reduced) * overlap**1.5
    wall_force = 0.0
    for wall in model.walls:
        members = np.asarray(wall.members, dtype=int)
        depth = np.maximum(-wall.gaps_m(lattice.positions_m[members], radii[members]), 0.0)
        wall_force += float(
            np.sum(model.wall_stiffness_pa(members) * np.sqrt(wall.contact_radii_m(radii[members])) * depth**1.5)
        )
    return Prestress(
        len(forces),
        float(overlap.max(initial=0.0)),
        float(forces.mean()) if len(forces) else 0.0,
        float(forces.max(initial=0.0)),
        wall_force,
    )
