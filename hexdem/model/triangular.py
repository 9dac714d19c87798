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

from dataclasses import replace

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.packing import LabelLine, Packing, unit_vector
from hexdem.model.walls import WALL_GROUP_GAP, CurvedWall, touching_walls

#: The step in (m, n) between consecutive sites along each of the lattice's twelve directions, by
#: angle from +x [deg]: odd multiples of 30° run along touching beads (spacing d), multiples of
#: 60° between them (spacing √3 d).
DIRECTION_STEPS = {
    0: (0, 2),
    30: (1, 1),
    60: (3, 1),
    90: (2, 0),
    120: (3, -1),
    150: (1, -1),
    180: (0, -2),
    -150: (-1, -1),
    -120: (-3, -1),
    -90: (-2, 0),
    -60: (-3, 1),
    -30: (-1, 1),
}
#: The paper's observation lines and the step in (m, n) between consecutive beads on each.
LINE_STEPS = {"0": DIRECTION_STEPS[0], "+30": DIRECTION_STEPS[30], "-30": DIRECTION_STEPS[-30]}
#: Index offsets of the three neighbours counted once per bond (paper's e₁, e₂, e₃).
BOND_STEPS = ((2, 0), (1, 1), (-1, 1))
#: The paper's lines from the struck bead, as a packing holds them (name, start: the struck bead, step).
PAPER_LINES = tuple(LabelLine(name, None, step) for name, step in LINE_STEPS.items())


def from_sites(
    labels, diameter_m: float = 1.0, wall_angles_deg=(), shape: str = "listed sites", struck=(0, 0)
) -> Packing:
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
        raise HexdemError(
            f"{shape}: site {{{odd[0, 0]}, {odd[0, 1]}}} has m + n odd: it is not a site of the "
            "hexagonal packing (m + n must be even)"
        )
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
    packing = Packing(
        labels=labels,
        positions_m=positions,
        diameters_m=np.full(len(labels), float(diameter_m)),
        diameter_m=float(diameter_m),
        struck=int(hit[0]),
        walls=(),
        shape=shape,
        label_lines=PAPER_LINES,
        bond_steps=BOND_STEPS,
    )
    normals = [unit_vector(a) for a in wall_angles_deg]
    return replace(packing, walls=touching_walls(packing, normals))


def _layer_sites(bounds) -> list[tuple[int, int]]:
    """Sites {m, n} of layers n = 0, 1, … (x = (√3/2) d n) holding lo_n <= m <= hi_n, m + n even."""
    return [(m, n) for n, (lo, hi) in enumerate(bounds) for m in range(lo, hi + 1) if (m + n) % 2 == 0]


def _circle_sites(radius: int, centre_x: float) -> list[tuple[int, int]]:
    """Sites {m, n} with n >= 0 within ``radius`` of the point (``centre_x``, 0), in bead diameters."""
    layers = int(np.floor(2 * (radius + centre_x) / np.sqrt(3) + 1e-9))
    heights = [
        int(np.floor(2 * np.sqrt(max(radius**2 - (np.sqrt(3) / 2 * n - centre_x) ** 2, 0.0)) + 1e-9))
        for n in range(layers + 1)
    ]
    return _layer_sites([(-h, h) for h in heights])


def without_sites(packing: Packing, vacancies) -> Packing:
    """``packing`` with the beads at the ``vacancies`` {m, n} left out; the walls stay where the
    full packing put them (a vacancy at an edge leaves a gap at the wall)."""
    vacancies = [tuple(int(v) for v in site) for site in vacancies]
    missing = [site for site in vacancies if packing.index_of(*site) is None]
    if missing:
        raise HexdemError(f"vacancy {{{missing[0][0]}, {missing[0][1]}}} is not a site of the {packing.shape}")
    if len(set(vacancies)) != len(vacancies):
        raise HexdemError("a vacancy is listed twice")
    removed = np.array([packing.index_of(*site) for site in vacancies], dtype=int)
    if packing.struck in removed:
        raise HexdemError("the struck bead cannot be a vacancy")
    keep = np.setdiff1d(np.arange(len(packing)), removed)
    new_index = np.full(len(packing), -1)
    new_index[keep] = np.arange(len(keep))
    walls = tuple(replace(wall, members=new_index[np.setdiff1d(wall.members, removed)]) for wall in packing.walls)
    shape = f"{packing.shape}, {len(removed)} vacanc{'y' if len(removed) == 1 else 'ies'}"
    return replace(
        packing,
        labels=packing.labels[keep],
        positions_m=packing.positions_m[keep],
        diameters_m=packing.diameters_m[keep],
        struck=int(new_index[packing.struck]),
        walls=walls,
        shape=shape,
        material_ids=packing.material_ids[keep],
    )


def hexagon(edge_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Packing:
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


def half_disc(radius_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Packing:
    """The beads within ``radius_beads`` d of the struck bead with x >= 0, and the struck edge's
    wall only (``radius_beads`` = 170: about 52,000 beads)."""
    if int(radius_beads) != radius_beads or radius_beads < 2:
        raise HexdemError(f"a half-disc needs a radius of at least 2 bead diameters, got {radius_beads}")
    radius = int(radius_beads)
    return from_sites(_circle_sites(radius, 0.0), diameter_m, (0,), f"half-disc, radius {radius} d", struck)


def half_hexagon(long_edge: int = 91, short_edge: int = 46, diameter_m: float = 1.0, struck=(0, 0)) -> Packing:
    """Half of a hexagon cut along its long diagonal (Fig. 4): that diagonal is the struck edge.

    ``long_edge`` = 2·``short_edge`` − 1 beads (91 and 46 → 3151 beads).
    """
    if int(short_edge) != short_edge or short_edge < 2 or long_edge != 2 * short_edge - 1:
        raise HexdemError(
            f"a half-hexagon needs long_edge = 2*short_edge - 1 >= 3, got long {long_edge}, short {short_edge}"
        )
    heights = [long_edge - 1 - n for n in range(int(short_edge))]
    return from_sites(
        _layer_sites([(-h, h) for h in heights]),
        diameter_m,
        (0, 180, 120, -120),
        f"half-hexagon, long edge {long_edge}, short edges {short_edge}",
        struck,
    )


def disc(radius_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Packing:
    """The sites within ``radius_beads`` d of a centre ``radius_beads`` d to the right of the
    struck bead (the disc's leftmost site), inside a curved wall touching the outermost beads
    (a circular basin, Hua & Van Gorder; the struck bead in its hole); 36,000 beads at radius 100."""
    if int(radius_beads) != radius_beads or radius_beads < 2:
        raise HexdemError(f"a disc needs a radius of at least 2 bead diameters, got {radius_beads}")
    radius = int(radius_beads)
    packing = from_sites(_circle_sites(radius, radius), diameter_m, (), f"disc, radius {radius} d", struck)
    centre = np.array([radius * diameter_m, 0.0])
    reach = np.linalg.norm(packing.positions_m - centre, axis=1) + packing.radii_m
    reach[packing.struck] = -np.inf  # in the hole: it does not decide where the wall is
    wall_radius = float(reach.max())
    members = np.flatnonzero(wall_radius - reach < WALL_GROUP_GAP * packing.diameter_m)
    return replace(packing, walls=(CurvedWall("wall_disc", (float(centre[0]), 0.0), wall_radius, members),))


def triangle(edge_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Packing:
    """Equilateral triangle with ``edge_beads`` per edge, N(N + 1)/2 beads: the struck edge
    vertical, its apex towards +x, the walls of a triangular basin (Hua & Van Gorder)."""
    if int(edge_beads) != edge_beads or edge_beads < 3:
        raise HexdemError(f"a triangle needs at least 3 beads per edge, got {edge_beads}")
    k = int(edge_beads) - 1
    sites = _layer_sites([(k % 2 - (k - n), k % 2 + (k - n)) for n in range(k + 1)])
    return from_sites(sites, diameter_m, (0, 120, -120), f"triangle, {k + 1} per edge", struck)


def parallelogram(edge_beads: int, depth_beads: int, diameter_m: float = 1.0, struck=(0, 0)) -> Packing:
    """Rhombus-like cell of ``depth_beads`` layers of ``edge_beads`` each (the struck edge
    vertical, the other two edges along +30°): a strip of the lattice with four walls."""
    for name, value in (("edge_beads", edge_beads), ("depth_beads", depth_beads)):
        if int(value) != value or value < 2:
            raise HexdemError(f"a parallelogram needs {name} >= 2, got {value}")
    k = int(edge_beads) - 1
    sites = _layer_sites([(k % 2 - k + n, k % 2 + k + n) for n in range(int(depth_beads))])
    return from_sites(
        sites, diameter_m, (0, 180, 120, -60), f"parallelogram, {k + 1} per edge, {int(depth_beads)} deep", struck
    )
