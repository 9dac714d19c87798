"""The walls of a basin: flat walls and the curved wall of a disc, each with the geometry that
both engines' sphere–wall Hertz contacts need (gap, inward normal, contact radius, curvature).

Each wall lists its ``members``, the beads that can touch it (:func:`~hexdem.model.packing.touching_walls`
places them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Wall:
    """A flat wall {x : normal·x = offset_m} that pushes beads along ``normal`` (inward).

    ``members`` are the indices of the beads that can touch it: the beads of that edge,
    minus the struck bead for the wall with the impact hole.
    """

    name: str
    normal: tuple[float, float]
    offset_m: float
    members: np.ndarray

    def gaps_m(self, positions_m, radii_m):
        """Signed gap between each bead surface and the wall (negative = overlap) [m]."""
        return np.asarray(positions_m) @ np.asarray(self.normal) - radii_m - self.offset_m

    def normals_at(self, positions_m) -> np.ndarray:
        """(N, 2) inward unit normals of the wall where beads at ``positions_m`` (N, 2) touch it."""
        return np.tile(np.asarray(self.normal, float), (len(positions_m), 1))

    def contact_radii_m(self, radii_m):
        """R_eff of the Hertz contact of beads of radii ``radii_m`` with the wall: R for a plane."""
        return np.asarray(radii_m, float)

    def curvatures_at(self, positions_m) -> np.ndarray:
        """(N,) 1/ρ, ρ the distance from each of ``positions_m`` to the wall's centre: 0 for a plane."""
        return np.zeros(len(positions_m))


@dataclass(frozen=True)
class CurvedWall:
    """The inside of a circle {x : |x − centre_m| = radius_m} (a cylinder in 3D), pushing beads
    towards its centre: the curved wall of a disc-shaped basin.

    ``members`` as for :class:`Wall`. The Hertz law of a sphere of radius r inside it uses
    LAMMPS's contact radius for a curved region, R_eff = r · 2R / (2R − r) (``region cylinder``
    stores the inside surface's radius as −2R and ``fix wall/gran/region`` combines it with the
    sphere's like a pair, r R' / (r + R'); measured: a sphere's contact time inside R = 3r is
    that of this R_eff to 0.1 µs), so that both engines share one law.
    """

    name: str
    centre_m: tuple[float, float]
    radius_m: float
    members: np.ndarray

    def gaps_m(self, positions_m, radii_m):
        """Signed gap between each bead surface and the wall (negative = overlap) [m]."""
        offsets = np.asarray(positions_m, float) - np.asarray(self.centre_m)
        return self.radius_m - np.linalg.norm(offsets, axis=-1) - radii_m

    def normals_at(self, positions_m) -> np.ndarray:
        """(N, 2) inward unit normals (towards the centre) where beads at ``positions_m`` touch it."""
        inward = np.asarray(self.centre_m) - np.asarray(positions_m, float).reshape(-1, 2)
        return inward / np.linalg.norm(inward, axis=1)[:, None]

    def contact_radii_m(self, radii_m):
        """R_eff = r · 2R / (2R − r) of beads of radii r = ``radii_m`` (see the class docstring)."""
        radii_m = np.asarray(radii_m, float)
        return radii_m * 2 * self.radius_m / (2 * self.radius_m - radii_m)

    def curvatures_at(self, positions_m) -> np.ndarray:
        """(N,) 1/ρ, ρ the distance from each of ``positions_m`` (N, 2) to the circle's centre."""
        return 1.0 / np.linalg.norm(np.asarray(positions_m, float) - np.asarray(self.centre_m), axis=1)


def wall_normals(walls, positions_m) -> tuple[np.ndarray, np.ndarray]:
    """(members (K,), inward normals (K, 2)) of every member of ``walls``, wall after wall, the
    normals where the beads at ``positions_m`` (all beads, N × 2) touch them."""
    members = np.concatenate([np.zeros(0, dtype=int)] + [wall.members for wall in walls]).astype(int)
    normals = np.concatenate([np.zeros((0, 2))] + [wall.normals_at(positions_m[wall.members]) for wall in walls])
    return members, normals
