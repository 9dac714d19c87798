"""The contacts of a :class:`~hexdem.model.granular.GranularModel` as the reference kernels need them:
Hertz coefficients in the run's units, the strikers' partners, the walls' geometry."""

from __future__ import annotations

import numpy as np

from hexdem.model.granular import GranularModel
from hexdem.model.units import UnitSystem
from hexdem.model.walls import wall_normals

#: A striker is bonded to every body closer than this many d to touching it at t = 0.
STRIKER_REACH = 0.5


def coefficient(stiffness_pa, r_eff_m, units: UnitSystem):
    """k sqrt(R_eff) [N/m^1.5] of a contact in ``units``: Hertz's A = k_n sqrt(R_eff), or Mindlin's
    k_t sqrt(R_eff) (whose force k_t a ξ = k_t sqrt(R_eff) sqrt(δ) ξ has the same units)."""
    return stiffness_pa * np.sqrt(r_eff_m) * units.length_m**1.5 / units.force_n


def reduced(a, b):
    """a b / (a + b): the reduced radius or mass of two bodies."""
    return a * b / (a + b)


def striker_bodies(model: GranularModel) -> tuple[np.ndarray, np.ndarray]:
    """(strikers, bodies): each striker paired with every body it touches or nearly touches at t = 0
    (none without one): its bead, the other beads and strikers within reach.

    Besides the struck bead, an oblique striker touches a neighbour of it (at 30° the bead
    {−2, 0}), and the spheres of a flat striker touch each other; LAMMPS, which counts every
    overlap, feels them all. Bonds are repulsive only, so a bond to a body that the striker
    never reaches costs nothing.
    """
    pos, radii = model.initial_positions_m(), model.diameters_m / 2
    strikers, bodies = [np.zeros(0, dtype=int)], [np.zeros(0, dtype=int)]
    for striker in range(len(model.lattice), model.n_bodies):
        gap = np.linalg.norm(pos[:striker] - pos[striker], axis=1) - radii[:striker] - radii[striker]
        near = np.flatnonzero(gap < STRIKER_REACH * model.lattice.diameter_m)
        strikers.append(np.full(len(near), striker))
        bodies.append(near)
    return np.concatenate(strikers), np.concatenate(bodies)


def wall_geometry(model: GranularModel):
    """(beads, inward normals (K, 2), rest gaps [m], curvatures [1/m], R_eff [m]) of every wall
    member: n the inward normal at the bead's rest position (its position at t = 0), curvature 1/ρ
    with ρ the distance from there to a curved wall's centre (0 for a plane), R_eff the Hertz
    contact radius."""
    lattice, walls = model.lattice, model.walls
    positions, radii = model.initial_positions_m()[:len(lattice)], lattice.radii_m
    beads, normals = wall_normals(walls, positions)
    gaps = np.concatenate([np.zeros(0)] + [wall.gaps_m(positions[wall.members], radii[wall.members]) for wall in walls])
    curvature = np.concatenate([np.zeros(0)] + [wall.curvatures_at(positions[wall.members]) for wall in walls])
    r_eff = np.concatenate([np.zeros(0)] + [wall.contact_radii_m(radii[wall.members]) for wall in walls])
    return beads, normals, gaps, curvature, r_eff
