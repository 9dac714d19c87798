"""Total mechanical energy of a granular state: kinetic + Hertz contact energy.

LAMMPS reports no potential energy for granular pairs, so hexdem computes it itself from
positions: a contact of overlap δ stores U = (2/5) k_n sqrt(R_eff) δ^{5/2} (the integral of
F = k_n sqrt(R_eff) δ^{3/2}; with equal spheres this is the paper's V = (2/5) A δ^{5/2}).
Every pair closer than the sum of radii counts, as in LAMMPS, not only lattice bonds.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from hexdem.model.granular import GranularModel


def contact_energy_j(positions_m, model: GranularModel) -> float:
    """Hertz energy [J] of all bead–bead and bead–wall overlaps at ``positions_m`` (n_bodies, 2)."""
    positions_m = np.asarray(positions_m, float)
    radii = model.diameters_m / 2
    pairs = cKDTree(positions_m).query_pairs(2 * radii.max(), output_type="ndarray")
    i, j = pairs.T
    overlap = radii[i] + radii[j] - np.linalg.norm(positions_m[i] - positions_m[j], axis=1)
    touching = overlap > 0
    r_eff = radii[i] * radii[j] / (radii[i] + radii[j])
    energy = 0.4 * model.pair_stiffness_pa * np.sum(np.sqrt(r_eff[touching]) * overlap[touching] ** 2.5)
    for wall in model.walls:
        members = wall.members
        depth = -wall.gaps_m(positions_m[members], radii[members])
        inside = depth > 0
        energy += 0.4 * model.wall_stiffness_pa * np.sum(np.sqrt(radii[members][inside]) * depth[inside] ** 2.5)
    return float(energy)


def kinetic_energy_j(velocities_m_s, model: GranularModel) -> float:
    """Translational kinetic energy Σ ½ M v² [J] (no torques act, so no rotation)."""
    return float(0.5 * np.sum(model.masses_kg * np.sum(np.asarray(velocities_m_s) ** 2, axis=1)))


def total_energy_j(positions_m, velocities_m_s, model: GranularModel) -> float:
    return kinetic_energy_j(velocities_m_s, model) + contact_energy_j(positions_m, model)
