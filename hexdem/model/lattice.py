"""Geometry of 2D hexagonal (triangular) packings of touching beads, indexed as in the paper.

Bead {m, n} (m + n even) of an ideal packing with diameter d sits at ::

    x = (√3/2) d n,   y = (d/2) m,

so its six touching neighbours are {m ± 2, n} and {m ± 1, n ± 1} (the paper's e₁, e₂, e₃,
Sec. III, rotated so that the struck edge is vertical). The struck bead is the centre bead
{0, 0} of the left edge n = 0; the wave runs towards +x.

Strike angles are measured from +x: 0° is perpendicular to the struck edge and pushes the
two neighbours at ±30°; 30° points along a line of touching beads. Observation lines
start at the struck bead (n = 0 on every line):

* ``"0"``   beads {0, 2k}: exactly on the x axis, spacing √3 d;
* ``"+30"`` beads {k, k}: touching beads at +30°, spacing d;
* ``"-30"`` beads {−k, k}: touching beads at −30°, spacing d.

Shapes: :func:`hexagon` (N beads per edge, 3N(N−1)+1 beads; N = 11 is the experiment),
:func:`half_hexagon` (Fig. 4: a hexagon cut along its long diagonal, which becomes the
struck edge) and :func:`half_disc` (the beads within a radius of the struck bead on the
packing's side of the struck edge: a front grows in it to that radius before it meets an
edge). Each shape carries its flat confining walls, placed touching the outermost beads
without compressing them, with the hole at the impact site; the half-disc has only the
struck edge's wall (its arc is free: an uncompressed packing's free edge sends nothing back).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.rays import ray_beads, ray_name
from hexdem.model.walls import CurvedWall, Wall

#: The step in (m, n) between consecutive sites along each of the lattice's twelve directions, by
#: angle from +x [deg]: odd multiples of 30° run along touching beads (spacing d), multiples of
#: 60° between them (spacing √3 d).
DIRECTION_STEPS = {0: (0, 2), 30: (1, 1), 60: (3, 1), 90: (2, 0), 120: (3, -1), 150: (1, -1), 180: (0, -2),
                   -150: (-1, -1), -120: (-3, -1), -90: (-2, 0), -60: (-3, 1), -30: (-1, 1)}
#: The paper's observation lines and the step in (m, n) between consecutive beads on each.
LINE_STEPS = {"0": DIRECTION_STEPS[0], "+30": DIRECTION_STEPS[30], "-30": DIRECTION_STEPS[-30]}
#: Index offsets of the three neighbours counted once per bond (paper's e₁, e₂, e₃).
BOND_STEPS = ((2, 0), (1, 1), (-1, 1))
#: A bead belongs to a wall's contact group when its gap to the wall is below this many d.
WALL_GROUP_GAP = 0.25


@dataclass(frozen=True)
class Lattice:
    """A finite hexagonal packing: indices, positions, diameters, walls and lines.

    ``indices`` (N, 2) int paper labels {m, n}; ``positions_m`` (N, 2) bead centres [m];
    ``diameters_m`` (N,) per-bead diameters [m] (all equal for the ideal lattice);
    ``diameter_m`` the nominal diameter d; ``struck`` index of the struck bead;
    ``walls`` the confining walls; ``shape`` a readable description; ``material_ids`` (N,)
    each bead's material, an index into the model's materials (None: all 0, the bead material);
    ``extra_lines`` observation lines besides the paper's three, each (name, start site (m, n),
    step (dm, dn)). ``ray_angles_deg``: None for the triangular lattice, whose labels are the
    paper's {m, n} and whose lines step along it; for any other packing (square, centered-square,
    chain, measured positions), whose ``indices`` are its builder's integer labels, the angles
    from +x of its observation lines, rays from the struck bead (:mod:`hexdem.model.rays`).
    """

    indices: np.ndarray
    positions_m: np.ndarray
    diameters_m: np.ndarray
    diameter_m: float
    struck: int
    walls: tuple[Wall | CurvedWall, ...]
    shape: str
    material_ids: np.ndarray | None = None
    extra_lines: tuple = ()
    ray_angles_deg: tuple[float, ...] | None = None

    def __post_init__(self):
        ids = np.zeros(len(self.indices), dtype=int) if self.material_ids is None else np.asarray(self.material_ids, int)
        if ids.shape != (len(self.indices),) or (len(ids) and ids.min() < 0):
            raise HexdemError(f"material_ids must hold one non-negative index per bead ({len(self.indices)})")
        object.__setattr__(self, "material_ids", ids)

    def __len__(self) -> int:
        return len(self.indices)

    @property
    def radii_m(self) -> np.ndarray:
        return self.diameters_m / 2.0

    @cached_property
    def _lookup(self) -> dict:
        """{(m, n): bead index}, made at the first lookup, not with every copy of the packing (for a
        million beads it takes 2.6 s, and building a model copies its packing three times)."""
        return dict(zip(map(tuple, self.indices.tolist()), range(len(self.indices))))

    def index_of(self, m: int, n: int) -> int | None:
        """The bead index of label {m, n}, or None when it is not in the packing."""
        return self._lookup.get((m, n))

    def bonds(self) -> np.ndarray:
        """(B, 2) index pairs of touching neighbours of a triangular packing, each pair once (the
        paper's e₁, e₂, e₃); other packings' contacts come from their geometry alone."""
        if self.ray_angles_deg is not None:
            raise HexdemError(f"{self.shape} is not a triangular packing: its contacts come from the geometry")
        pairs = [(i, j) for i, (m, n) in enumerate(self.indices.tolist())
                 for dm, dn in BOND_STEPS if (j := self.index_of(m + dm, n + dn)) is not None]
        return np.array(pairs, dtype=int).reshape(-1, 2)

    def _line_starts(self) -> dict:
        """{line name: (start site, step)}: the paper's lines from the struck bead, then the extra ones."""
        struck = tuple(int(v) for v in self.indices[self.struck])
        return {**{name: (struck, step) for name, step in LINE_STEPS.items()},
                **{name: (tuple(site), tuple(step)) for name, site, step in self.extra_lines}}

    def line(self, name: str) -> np.ndarray:
        """Bead indices on observation line ``name`` ("0", "+30", "-30" from the struck bead, or an
        extra line from its own start; a ray's name on other packings), from its start on."""
        if self.ray_angles_deg is not None:
            rays = {ray_name(angle): angle for angle in self.ray_angles_deg}
            if name not in rays:
                raise HexdemError(f"unknown observation line {name!r}; known: {', '.join(rays)}")
            return ray_beads(self.positions_m, self.struck, rays[name], self.diameter_m)
        starts = self._line_starts()
        if name not in starts:
            raise HexdemError(f"unknown observation line {name!r}; known: {', '.join(starts)}")
        (m0, n0), (dm, dn) = starts[name]
        beads, k = [], 0
        while (i := self.index_of(m0 + k * dm, n0 + k * dn)) is not None:
            beads.append(i)
            k += 1
        return np.array(beads, dtype=int)

    def lines(self) -> dict[str, np.ndarray]:
        names = (self._line_starts() if self.ray_angles_deg is None
                 else [ray_name(angle) for angle in self.ray_angles_deg])
        return {name: self.line(name) for name in names}

    def with_geometry(self, positions_m, diameters_m) -> "Lattice":
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


def from_sites(labels, diameter_m: float = 1.0, wall_angles_deg=(), shape: str = "listed sites",
               struck=(0, 0)) -> Lattice:
    """The packing of the listed sites {m, n} (m + n even), with flat walls touching it whose
    inward normals point at ``wall_angles_deg`` (none: a free packing), struck at ``struck``.

    Any packing is this: the built-in shapes list their sites, and a user's list (a vacancy is
    a site left out) works the same everywhere downstream."""
    if not (isinstance(diameter_m, (int, float)) and diameter_m > 0):
        raise HexdemError(f"bead diameter must be > 0 m, got {diameter_m}")
    try:
        labels = np.asarray(labels, dtype=int).reshape(-1, 2)
    except (TypeError, ValueError):
        raise HexdemError(f"{shape}: sites must be pairs of integers [m, n]") from None
    odd = labels[(labels.sum(axis=1) % 2) != 0]
    if len(odd):
        raise HexdemError(f"{shape}: site {{{odd[0, 0]}, {odd[0, 1]}}} has m + n odd: it is not a site of the "
                          "hexagonal packing (m + n must be even)")
    if len(labels) < 1:
        raise HexdemError(f"{shape}: a packing needs at least 1 bead, got none")
    low = labels.min(axis=0)
    keys = (labels[:, 0] - low[0]) * (int(np.ptp(labels[:, 1])) + 1) + labels[:, 1] - low[1]
    _, first, counts = np.unique(keys, return_index=True, return_counts=True)  # one number a site: a quick sort
    if np.any(counts > 1):
        m, n = labels[first[np.argmax(counts > 1)]]
        raise HexdemError(f"{shape}: site {{{m}, {n}}} is listed twice")
    hit = np.flatnonzero((labels[:, 0] == struck[0]) & (labels[:, 1] == struck[1]))
    if not len(hit):
        raise HexdemError(f"{shape}: the struck site {{{struck[0]}, {struck[1]}}} is not in the packing")
    positions = np.column_stack([np.sqrt(3) / 2 * labels[:, 1], labels[:, 0] / 2.0]) * diameter_m
    lattice = Lattice(indices=labels, positions_m=positions,
                      diameters_m=np.full(len(labels), float(diameter_m)), diameter_m=float(diameter_m),
                      struck=int(hit[0]), walls=(), shape=shape)
    normals = [unit_vector(a) for a in wall_angles_deg]
    return replace(lattice, walls=touching_walls(lattice, normals))


def _layer_sites(bounds) -> list[tuple[int, int]]:
    """Sites {m, n} of layers n = 0, 1, … (x = (√3/2) d n) holding lo_n <= m <= hi_n, m + n even."""
    return [(m, n) for n, (lo, hi) in enumerate(bounds) for m in range(lo, hi + 1) if (m + n) % 2 == 0]


def _circle_sites(radius: int, centre_x: float) -> list[tuple[int, int]]:
    """Sites {m, n} with n >= 0 within ``radius`` of the point (``centre_x``, 0), in bead diameters."""
    layers = int(np.floor(2 * (radius + centre_x) / np.sqrt(3) + 1e-9))
    heights = [int(np.floor(2 * np.sqrt(max(radius**2 - (np.sqrt(3) / 2 * n - centre_x) ** 2, 0.0)) + 1e-9))
               for n in range(layers + 1)]
    return _layer_sites([(-h, h) for h in heights])


def without_sites(lattice: Lattice, vacancies) -> Lattice:
    """``lattice`` with the beads at the ``vacancies`` {m, n} left out; the walls stay where the
    full packing put them (a vacancy at an edge leaves a gap at the wall)."""
    vacancies = [tuple(int(v) for v in site) for site in vacancies]
    missing = [site for site in vacancies if lattice.index_of(*site) is None]
    if missing:
        raise HexdemError(f"vacancy {{{missing[0][0]}, {missing[0][1]}}} is not a site of the {lattice.shape}")
    if len(set(vacancies)) != len(vacancies):
        raise HexdemError("a vacancy is listed twice")
    removed = np.array([lattice.index_of(*site) for site in vacancies], dtype=int)
    if lattice.struck in removed:
        raise HexdemError("the struck bead cannot be a vacancy")
    keep = np.setdiff1d(np.arange(len(lattice)), removed)
    new_index = np.full(len(lattice), -1)
    new_index[keep] = np.arange(len(keep))
    walls = tuple(replace(wall, members=new_index[np.setdiff1d(wall.members, removed)]) for wall in lattice.walls)
    shape = f"{lattice.shape}, {len(removed)} vacanc{'y' if len(removed) == 1 else 'ies'}"
    return replace(lattice, indices=lattice.indices[keep], positions_m=lattice.positions_m[keep],
                   diameters_m=lattice.diameters_m[keep], struck=int(new_index[lattice.struck]), walls=walls,
                   shape=shape, material_ids=lattice.material_ids[keep])


#: A struck bead sits in a hole of every wall whose inward normal is within 60° of its motion
#: (the wall it would be pushed through; not the other wall of a corner bead struck along an edge).
HOLE_COSINE = 0.5 + 1e-9


def without_hole(lattice: Lattice) -> Lattice:
    """``lattice`` with its struck bead a member of every wall it touches: the walls whole, for
    impacts that each cut their own hole (:func:`with_holes`)."""
    bead, walls = lattice.struck, []
    for wall in lattice.walls:
        gap = wall.gaps_m(lattice.positions_m[[bead]], lattice.radii_m[[bead]])[0]
        if gap < WALL_GROUP_GAP * lattice.diameter_m and bead not in wall.members:
            wall = replace(wall, members=np.sort(np.append(wall.members, bead)))
        walls.append(wall)
    return replace(lattice, walls=tuple(walls))


def with_holes(lattice: Lattice, beads, directions) -> Lattice:
    """``lattice`` with each of ``beads`` (indices) taken out of the walls it would be pushed
    through moving along its unit vector of ``directions`` (N, 2): the holes of several impacts.
    A wall left without members is dropped (an edge struck whole)."""
    walls = []
    for wall in lattice.walls:
        members = set(wall.members.tolist())
        for bead, direction in zip(beads, np.asarray(directions, float).reshape(-1, 2)):
            if bead in members and wall.normals_at(lattice.positions_m[[bead]])[0] @ direction > HOLE_COSINE:
                members.discard(bead)
        if members:
            walls.append(replace(wall, members=np.array(sorted(members), dtype=int)))
    return replace(lattice, walls=tuple(walls))


def facing_edge(lattice: Lattice, normal, hole: int | None = None) -> tuple[float, np.ndarray]:
    """(offset [m], beads) of the packing's edge facing the inward ``normal``: the extreme of
    normal·x − r over the beads, and the beads within :data:`WALL_GROUP_GAP` d of it; ``hole``, a
    bead index, neither counts nor decides where the edge is."""
    reach = lattice.positions_m @ np.asarray(normal) - lattice.radii_m
    if hole is not None:
        reach[hole] = np.inf
    offset = float(reach.min())
    return offset, np.flatnonzero(reach - offset < WALL_GROUP_GAP * lattice.diameter_m)


def touching_walls(lattice: Lattice, normals) -> tuple[Wall, ...]:
    """Flat walls with the given inward normals, each touching the packing without overlap.

    The wall whose normal is +x (the struck edge) has a hole: the struck bead is not a member
    and, sitting in the hole, does not decide where that wall is (it may protrude when the
    diameters vary).
    """
    walls = []
    for normal in normals:
        normal = (float(normal[0]), float(normal[1]))
        offset, members = facing_edge(lattice, normal, lattice.struck if np.isclose(normal[0], 1.0) else None)
        angle = int(round(np.degrees(np.arctan2(normal[1], normal[0]))))
        walls.append(Wall(f"wall_{angle:03d}".replace("-", "m"), normal, offset, members))
    return tuple(walls)


def hexagon(edge_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Lattice:
    """Regular hexagon with ``edge_beads`` beads per edge, struck edge vertical (N = 11: 331 beads).

    With an even count the struck edge has two middle beads; the struck bead {0, 0} is the
    lower one (the packing is shifted up by half a bead).
    """
    if int(edge_beads) != edge_beads or edge_beads < 2:
        raise HexdemError(f"a hexagon needs at least 2 beads per edge, got {edge_beads}")
    k = int(edge_beads) - 1
    heights = [k + min(n, 2 * k - n) for n in range(2 * k + 1)]
    sites = _layer_sites([(k % 2 - h, k % 2 + h) for h in heights])
    return from_sites(sites, diameter_m, (0, 180, 60, -60, 120, -120), f"hexagon, {k + 1} per edge", struck)


def half_disc(radius_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Lattice:
    """The beads within ``radius_beads`` d of the struck bead with x >= 0, and the struck edge's
    wall only (``radius_beads`` = 170: about 52,000 beads)."""
    if int(radius_beads) != radius_beads or radius_beads < 2:
        raise HexdemError(f"a half-disc needs a radius of at least 2 bead diameters, got {radius_beads}")
    radius = int(radius_beads)
    return from_sites(_circle_sites(radius, 0.0), diameter_m, (0,), f"half-disc, radius {radius} d", struck)


def half_hexagon(long_edge: int = 91, short_edge: int = 46, diameter_m: float = 1.0, struck=(0, 0)) -> Lattice:
    """Half of a hexagon cut along its long diagonal (Fig. 4): that diagonal is the struck edge.

    ``long_edge`` = 2·``short_edge`` − 1 beads (91 and 46 → 3151 beads).
    """
    if int(short_edge) != short_edge or short_edge < 2 or long_edge != 2 * short_edge - 1:
        raise HexdemError(f"a half-hexagon needs long_edge = 2*short_edge - 1 >= 3, "
                          f"got long {long_edge}, short {short_edge}")
    heights = [long_edge - 1 - n for n in range(int(short_edge))]
    return from_sites(_layer_sites([(-h, h) for h in heights]), diameter_m, (0, 180, 120, -120),
                      f"half-hexagon, long edge {long_edge}, short edges {short_edge}", struck)


def disc(radius_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Lattice:
    """The sites within ``radius_beads`` d of a centre ``radius_beads`` d to the right of the
    struck bead (the disc's leftmost site), inside a curved wall touching the outermost beads
    (a circular basin, Hua & Van Gorder; the struck bead in its hole); 36,000 beads at radius 100."""
    if int(radius_beads) != radius_beads or radius_beads < 2:
        raise HexdemError(f"a disc needs a radius of at least 2 bead diameters, got {radius_beads}")
    radius = int(radius_beads)
    lattice = from_sites(_circle_sites(radius, radius), diameter_m, (), f"disc, radius {radius} d", struck)
    centre = np.array([radius * diameter_m, 0.0])
    reach = np.linalg.norm(lattice.positions_m - centre, axis=1) + lattice.radii_m
    reach[lattice.struck] = -np.inf  # in the hole: it does not decide where the wall is
    wall_radius = float(reach.max())
    members = np.flatnonzero(wall_radius - reach < WALL_GROUP_GAP * lattice.diameter_m)
    return replace(lattice, walls=(CurvedWall("wall_disc", (float(centre[0]), 0.0), wall_radius, members),))


def triangle(edge_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Lattice:
    """Equilateral triangle with ``edge_beads`` per edge, N(N + 1)/2 beads: the struck edge
    vertical, its apex towards +x, the walls of a triangular basin (Hua & Van Gorder)."""
    if int(edge_beads) != edge_beads or edge_beads < 3:
        raise HexdemError(f"a triangle needs at least 3 beads per edge, got {edge_beads}")
    k = int(edge_beads) - 1
    sites = _layer_sites([(k % 2 - (k - n), k % 2 + (k - n)) for n in range(k + 1)])
    return from_sites(sites, diameter_m, (0, 120, -120), f"triangle, {k + 1} per edge", struck)


def parallelogram(edge_beads: int, depth_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Lattice:
    """Rhombus-like cell of ``depth_beads`` layers of ``edge_beads`` each (the struck edge
    vertical, the other two edges along +30°): a strip of the lattice with four walls."""
    for name, value in (("edge_beads", edge_beads), ("depth_beads", depth_beads)):
        if int(value) != value or value < 2:
            raise HexdemError(f"a parallelogram needs {name} >= 2, got {value}")
    k = int(edge_beads) - 1
    sites = _layer_sites([(k % 2 - k + n, k % 2 + k + n) for n in range(int(depth_beads))])
    return from_sites(sites, diameter_m, (0, 180, 120, -60),
                      f"parallelogram, {k + 1} per edge, {int(depth_beads)} deep", struck)
