"""The walls of a basin: flat walls and the curved wall of a disc, each with the geometry that
both engines' sphere–wall Hertz contacts need (gap, inward normal, contact radius, curvature).

Each wall lists its ``members``, the beads that can touch it (:func:`touching_walls`
places them); the wall editing of a packing (its walls touching it, the holes its impacts cut) is
here too, reading the packing's beads (a :class:`~hexdem.model.packing.Packing`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from hexdem.errors import HexdemError

#: A bead belongs to a wall's contact group when its gap to the wall is below this many d.
WALL_GROUP_GAP = 0.25
#: A struck bead sits in a hole of every wall whose inward normal is within 60° of its motion
#: (the wall it would be pushed through; not the other wall of a corner bead struck along an edge).
HOLE_COSINE = 0.5 + 1e-9


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


def without_hole(packing):
    """``packing`` with its struck bead a member of every wall it touches: the walls whole, for
    impacts that each cut their own hole (:func:`with_holes`)."""
    bead, walls = packing.struck, []
    for wall in packing.walls:
        gap = wall.gaps_m(packing.positions_m[[bead]], packing.radii_m[[bead]])[0]
        if gap < WALL_GROUP_GAP * packing.diameter_m and bead not in wall.members:
            wall = replace(wall, members=np.sort(np.append(wall.members, bead)))
        walls.append(wall)
    return replace(packing, walls=tuple(walls))


def with_holes(packing, beads, directions):
    """``packing`` with each of ``beads`` (indices) taken out of the walls it would be pushed
    through moving along its unit vector of ``directions`` (N, 2): the holes of several impacts.
    A wall left without members is dropped (an edge struck whole)."""
    walls = []
    for wall in packing.walls:
        members = set(wall.members.tolist())
        for bead, direction in zip(beads, np.asarray(directions, float).reshape(-1, 2)):
            if bead in members and wall.normals_at(packing.positions_m[[bead]])[0] @ direction > HOLE_COSINE:
                members.discard(bead)
        if members:
            walls.append(replace(wall, members=np.array(sorted(members), dtype=int)))
    return replace(packing, walls=tuple(walls))


def facing_edge(packing, normal, hole: int | None = None) -> tuple[float, np.ndarray]:
    """(offset [m], beads) of the packing's edge facing the inward ``normal``: the extreme of
    normal·x − r over the beads, and the beads within :data:`WALL_GROUP_GAP` d of it; ``hole``, a
    bead index, neither counts nor decides where the edge is."""
    reach = packing.positions_m @ np.asarray(normal) - packing.radii_m
    if hole is not None:
        reach[hole] = np.inf
    offset = float(reach.min())
    return offset, np.flatnonzero(reach - offset < WALL_GROUP_GAP * packing.diameter_m)


def touching_walls(packing, normals) -> tuple[Wall, ...]:
    """Flat walls with the given inward normals, each touching the packing without overlap.

    The wall whose normal is +x (the struck edge) has a hole: the struck bead is not a member
    and, sitting in the hole, does not decide where that wall is (it may protrude when the
    diameters vary).
    """
    walls = []
    for normal in normals:
        normal = (float(normal[0]), float(normal[1]))
        offset, members = facing_edge(packing, normal, packing.struck if np.isclose(normal[0], 1.0) else None)
        angle = int(round(np.degrees(np.arctan2(normal[1], normal[0]))))
        walls.append(Wall(f"wall_{angle:03d}".replace("-", "m"), normal, offset, members))
    return tuple(walls)


def _wall_members(packing) -> set[int]:
    return {int(b) for wall in packing.walls for b in wall.members}


def cut_holes(packing, impacts) -> tuple:
    """(``packing`` (its walls whole, :func:`without_hole`) with a hole for
    the bead of each of ``impacts`` (:func:`~hexdem.model.impacts.resolve_impacts`'s, each naming its bead) in every
    wall it is pushed through, the beads that left every wall). An
    impact on a wall bead that points out through that wall (within 60° of its outward normal;
    a corner bead may still be pushed along or against its other wall) is refused."""
    beads = [impact.bead for impact in impacts]
    for impact, bead in zip(impacts, beads):
        for wall in packing.walls:
            if (
                bead in wall.members
                and wall.normals_at(packing.positions_m[[bead]])[0] @ impact.direction < -HOLE_COSINE
            ):
                m, n = packing.labels[bead]
                raise HexdemError(
                    f"the impact on bead {{{m}, {n}}} at {impact.angle_deg:g}° points out of the packing "
                    f"through {wall.name}: strike it inwards"
                )
    holed = with_holes(packing, beads, [impact.direction for impact in impacts])
    return holed, _wall_members(packing) - _wall_members(holed)
