"""A packing of measured positions: a CSV of bead centres, diameters and (optionally) materials.

``packing_file`` is a CSV with the header ``x,y,diameter[,material]``, in metres, one bead per
line; beads are numbered by line from 0 (label {0, k}), and ``struck_bead`` names the struck one.
Walls: ``"none"`` (a free packing) or ``"hull"``: a flat wall along each edge of the convex hull
of the centres, moved out to touch the outer beads without compressing them, the struck bead in a
hole of the walls its strike pushes it through. Its lines are the rays at 0° and ±30° from the
struck bead (:mod:`hexdem.model.rays`), the paper's lines on a hexagonal packing.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from hexdem.common.io import read_text
from hexdem.errors import HexdemError
from hexdem.model.packing import Packing
from hexdem.model.placed import placed_packing
from hexdem.model.walls import touching_walls, with_holes

WALLS = ("none", "hull")
#: The rays of a packing read from a file: the paper's three directions.
FILE_RAYS_DEG = (0, 30, -30)
#: A file's diameters must lie within this factor of the run's nominal diameter_m, which sets the
#: time step and the units.
DIAMETER_RANGE = 2.0


@dataclass(frozen=True)
class PackingRows:
    """The file's beads: ``positions_m`` (N, 2), ``diameters_m`` (N,), ``materials`` (N,) names
    (empty strings where the file gives none)."""

    positions_m: np.ndarray
    diameters_m: np.ndarray
    materials: tuple[str, ...]


def read_packing_rows(path) -> PackingRows:
    """The beads of the CSV at ``path`` (see the module docstring), or a one-line HexdemError."""
    path = Path(path)
    rows = list(csv.reader(line for line in read_text(path, "packing_file").splitlines() if line.strip()))
    header = [cell.strip() for cell in rows[0]] if rows else []
    if header not in (["x", "y", "diameter"], ["x", "y", "diameter", "material"]):
        raise HexdemError(f"packing_file {path}: a packing starts with the header line 'x,y,diameter[,material]'")
    if len(rows) < 2:
        raise HexdemError(f"packing_file {path} lists no bead")
    try:
        numbers = np.array([[float(cell) for cell in row[:3]] for row in rows[1:] if len(row) == len(header)])
    except ValueError:
        numbers = np.zeros((0, 3))
    if numbers.shape != (len(rows) - 1, 3) or not np.all(np.isfinite(numbers)):
        raise HexdemError(
            f"packing_file {path}: every line after the header must hold {len(header)} values, "
            "x, y and diameter finite numbers [m]"
        )
    materials = tuple(row[3].strip() if len(header) == 4 else "" for row in rows[1:])
    return PackingRows(numbers[:, :2], numbers[:, 2], materials)


def hull_normals(positions_m) -> list[np.ndarray]:
    """Inward unit normals of the edges of the convex hull of ``positions_m`` (N, 2)."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(positions_m)
    except (QhullError, ValueError):
        raise HexdemError('walls = "hull" needs at least 3 beads not all on one line') from None
    return [-equation[:2] / np.linalg.norm(equation[:2]) for equation in hull.equations]


def packing_from_file(
    path, beads: PackingRows, diameter_m: float, struck_bead: int, walls: str, strike_direction
) -> Packing:
    """The packing of the ``beads`` read from ``packing_file`` ``path`` (:func:`read_packing_rows`;
    nominal ``diameter_m``), struck at row ``struck_bead`` along the unit vector
    ``strike_direction``, with ``walls``."""
    if walls not in WALLS:
        raise HexdemError(f"walls must be one of {', '.join(WALLS)}, got {walls!r}")
    if not 0 <= struck_bead < len(beads.diameters_m):
        raise HexdemError(f"struck_bead {struck_bead} is not a bead of {path} (rows 0 to {len(beads.diameters_m) - 1})")
    ratio = beads.diameters_m / diameter_m
    if ratio.min() < 1 / DIAMETER_RANGE or ratio.max() > DIAMETER_RANGE:
        raise HexdemError(
            f"packing_file {path}: diameters {beads.diameters_m.min():.4g} to {beads.diameters_m.max():.4g} m "
            f"are not within a factor {DIAMETER_RANGE:g} of diameter_m = {diameter_m:g}; set diameter_m "
            "to the packing's nominal diameter"
        )
    labels = np.column_stack([np.zeros(len(ratio), dtype=int), np.arange(len(ratio))])
    packing = placed_packing(
        labels,
        beads.positions_m,
        beads.diameters_m,
        diameter_m,
        (),
        f"packing of {Path(path).name}, {len(ratio)} beads",
        (0, struck_bead),
        FILE_RAYS_DEG,
    )
    if walls == "none":
        return packing
    hull = [
        replace(wall, name=f"wall_hull_{k}")
        for k, wall in enumerate(touching_walls(packing, hull_normals(beads.positions_m)))
    ]
    return with_holes(replace(packing, walls=tuple(hull)), [packing.struck], [strike_direction])
