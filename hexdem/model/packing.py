"""A packing: the beads' positions, diameters and materials, the walls around them and the
lines along which a pulse is observed.

A :class:`Packing` is data, as ASE's ``Atoms`` is: it says nothing of how it was built. Its
builders are plain functions that return one: the triangular lattice's shapes
(:mod:`hexdem.model.triangular`), the square and centered-square crystals
(:mod:`hexdem.model.square_crystals`), the chain (:mod:`hexdem.model.chain`) and measured positions
(:mod:`hexdem.model.packing_file`), the last three through :func:`~hexdem.model.placed.placed_packing`.

Each bead carries its builder's integer label, a pair: the paper's {m, n} on the triangular
lattice, row and column on a square crystal, {0, k} along a chain or a file. A line is found one
of two ways, both held as data: walking the labels one step at a time from a start (the triangular
lattice's lines, :attr:`Packing.label_lines`), or as a ray from the struck bead
(:attr:`Packing.rays_deg`, :mod:`hexdem.model.rays`). Contacts are found from the geometry; a
packing whose labels also say which beads touch lists those steps (:attr:`Packing.bond_steps`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import NamedTuple

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.rays import ray_beads, ray_name
from hexdem.model.walls import CurvedWall, Wall

#: A bead belongs to a wall's contact group when its gap to the wall is below this many d.
WALL_GROUP_GAP = 0.25
#: A struck bead sits in a hole of every wall whose inward normal is within 60° of its motion
#: (the wall it would be pushed through; not the other wall of a corner bead struck along an edge).
HOLE_COSINE = 0.5 + 1e-9


class LabelLine(NamedTuple):
    """An observation line on the labels: from label ``start`` (None: the struck bead's) on,
    one label step ``step`` (dm, dn) at a time."""

    name: str
    start: tuple[int, int] | None
    step: tuple[int, int]


@dataclass(frozen=True, eq=False)
class Packing:
    """A finite 2D packing of beads: labels, positions, diameters, materials, walls and lines.

    ``labels`` (N, 2) int, the builder's labels (the paper's {m, n} on the triangular lattice);
    ``positions_m`` (N, 2) bead centres [m]; ``diameters_m`` (N,) per-bead diameters [m];
    ``diameter_m`` the nominal diameter d; ``struck`` index of the struck bead; ``walls`` the
    confining walls; ``shape`` a readable description; ``material_ids`` (N,) each bead's material,
    an index into the model's materials (None: all 0, the bead material).

    Lines: ``label_lines``, each a :class:`LabelLine`, holds the beads from the start on, one label step at a time, until the packing ends;
    ``rays_deg`` the angles from +x of the rays from the struck bead (:mod:`hexdem.model.rays`),
    named by :func:`~hexdem.model.rays.ray_name`. ``bond_steps``: the label steps between touching
    neighbours, each bond once, where the labels say which beads touch (the triangular lattice's
    e₁, e₂, e₃); empty where contacts come from the geometry alone.
    """

    labels: np.ndarray
    positions_m: np.ndarray
    diameters_m: np.ndarray
    diameter_m: float
    struck: int
    walls: tuple[Wall | CurvedWall, ...]
    shape: str
    material_ids: np.ndarray | None = None
    label_lines: tuple[LabelLine, ...] = ()
    rays_deg: tuple[float, ...] = ()
    bond_steps: tuple[tuple[int, int], ...] = ()

    def __post_init__(self):
        ids = np.zeros(len(self.labels), dtype=int) if self.material_ids is None else np.asarray(self.material_ids, int)
        if ids.shape != (len(self.labels),) or (len(ids) and ids.min() < 0):
            raise HexdemError(f"material_ids must hold one non-negative index per bead ({len(self.labels)})")
        object.__setattr__(self, "material_ids", ids)

    def __len__(self) -> int:
        return len(self.labels)

    @property
    def radii_m(self) -> np.ndarray:
        return self.diameters_m / 2.0

    @cached_property
    def _lookup(self) -> dict:
        """{label: bead index}, made at the first lookup, not with every copy of the packing (for a
        million beads it takes 2.6 s, and building a model copies its packing three times)."""
        return dict(zip(map(tuple, self.labels.tolist()), range(len(self.labels))))

    def index_of(self, m: int, n: int) -> int | None:
        """The bead index of label {m, n}, or None when it is not in the packing."""
        return self._lookup.get((m, n))

    def bonds(self) -> np.ndarray:
        """(B, 2) index pairs of touching neighbours read from the labels (:attr:`bond_steps`),
        each pair once; a packing without them finds its contacts from the geometry alone."""
        if not self.bond_steps:
            raise HexdemError(f"{self.shape} is not a triangular packing: its contacts come from the geometry")
        pairs = [(i, j) for i, (m, n) in enumerate(self.labels.tolist())
                 for dm, dn in self.bond_steps if (j := self.index_of(m + dm, n + dn)) is not None]
        return np.array(pairs, dtype=int).reshape(-1, 2)

    def _line_names(self) -> list[str]:
        return [name for name, _, _ in self.label_lines] + [ray_name(angle) for angle in self.rays_deg]

    def line(self, name: str) -> np.ndarray:
        """Bead indices on observation line ``name``, from its start on (the struck bead first on
        a ray and on a label line from the struck bead)."""
        walks = {line_name: (start, step) for line_name, start, step in self.label_lines}
        rays = {ray_name(angle): angle for angle in self.rays_deg}
        if name in walks:
            start, (dm, dn) = walks[name]
            m0, n0 = (int(v) for v in (self.labels[self.struck] if start is None else start))
            beads, k = [], 0
            while (i := self.index_of(m0 + k * dm, n0 + k * dn)) is not None:
                beads.append(i)
                k += 1
            return np.array(beads, dtype=int)
        if name in rays:
            return ray_beads(self.positions_m, self.struck, rays[name], self.diameter_m)
        raise HexdemError(f"unknown observation line {name!r}; known: {', '.join(self._line_names())}")

    def lines(self) -> dict[str, np.ndarray]:
        return {name: self.line(name) for name in self._line_names()}

    def with_geometry(self, positions_m, diameters_m) -> Packing:
        """The same labels with new positions and diameters, walls re-placed to touch them."""
        moved = replace(self, positions_m=np.asarray(positions_m, float),
                        diameters_m=np.asarray(diameters_m, float), walls=())
        return replace(moved, walls=touching_walls(moved, [w.normal for w in self.walls]))


def unit_vector(angle_deg: float) -> np.ndarray:
    """(cos, sin) of ``angle_deg`` from +x."""
    angle = float(angle_deg)
    return np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])


def strike_direction(angle_deg: float) -> np.ndarray:
    """Unit vector of a strike at ``angle_deg`` from +x; it must point into the packing."""
    angle = float(angle_deg)
    if not np.isfinite(angle) or abs(angle) >= 90.0:
        raise HexdemError(f"strike angle {angle_deg}° does not point into the packing; "
                          "use an angle in (-90°, 90°), e.g. 0 or 30")
    return unit_vector(angle)


def without_hole(packing: Packing) -> Packing:
    """``packing`` with its struck bead a member of every wall it touches: the walls whole, for
    impacts that each cut their own hole (:func:`with_holes`)."""
    bead, walls = packing.struck, []
    for wall in packing.walls:
        gap = wall.gaps_m(packing.positions_m[[bead]], packing.radii_m[[bead]])[0]
        if gap < WALL_GROUP_GAP * packing.diameter_m and bead not in wall.members:
            wall = replace(wall, members=np.sort(np.append(wall.members, bead)))
        walls.append(wall)
    return replace(packing, walls=tuple(walls))


def with_holes(packing: Packing, beads, directions) -> Packing:
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


def facing_edge(packing: Packing, normal, hole: int | None = None) -> tuple[float, np.ndarray]:
    """(offset [m], beads) of the packing's edge facing the inward ``normal``: the extreme of
    normal·x − r over the beads, and the beads within :data:`WALL_GROUP_GAP` d of it; ``hole``, a
    bead index, neither counts nor decides where the edge is."""
    reach = packing.positions_m @ np.asarray(normal) - packing.radii_m
    if hole is not None:
        reach[hole] = np.inf
    offset = float(reach.min())
    return offset, np.flatnonzero(reach - offset < WALL_GROUP_GAP * packing.diameter_m)


def touching_walls(packing: Packing, normals) -> tuple[Wall, ...]:
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
