"""Square and centered-square crystals: the seed paper's contrast to the hexagonal packing, and
the square crystal with spherical interstitial intruders of Szelengowicz, Kevrekidis & Daraio
(Phys. Rev. E 86, 061306, 2012). Every bead is a sphere and every contact sphere on sphere: the
centered-square experiments of Leonard & Daraio put cylinders in the cells, which this model
does not describe.

Both stand in a square basin of four walls, struck in the middle of the left column
(label {0, 0}) through a hole of the left wall. A square crystal of ``rows`` × ``columns``
beads of diameter d has bead {m, n} (row m, column n) at x = n d, y = m d: a strike along +x
meets a straight row of touching beads, a chain, and nothing else (its neighbours touch it at
90°, where a normal force has no component along the row). A centered-square crystal adds an
interstitial bead at the centre of each square cell: corner beads {2i, 2j} at x = j a, y = i a,
interstitials {2i + 1, 2j + 1} at the cells' centres, where a = max(d, (d + d_s)/√2) keeps the
large beads touching along the rows when the interstitial (d_s) fits, and the interstitials
touching the corners when it does not. The default d_s = (√2 − 1) d touches both.
"""

from __future__ import annotations

import math

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.packing import Packing
from hexdem.model.placed import placed_packing

#: The square basin's walls (inward normals) and the lines of a square packing (rays from the struck bead).
SQUARE_WALLS_DEG = (0, 180, 90, -90)
SQUARE_RAYS_DEG = (0, 45, -45, 90, -90)


#: The fewest rows and columns of a square or centered-square crystal: the struck bead's column
#: holds another bead, which places the wall it is struck through, and its row another, which
#: carries the pulse.
MIN_GRID = 2


def _grid_size(rows, columns) -> tuple[int, int]:
    if not all(int(value) == value and value >= MIN_GRID for value in (rows, columns)):
        raise HexdemError(
            f"a square crystal needs at least {MIN_GRID} rows and {MIN_GRID} columns, got {rows} x {columns}"
        )
    return int(rows), int(columns)


def square(rows: int, columns: int, diameter_m: float, struck=(0, 0)) -> Packing:
    """``rows`` × ``columns`` touching beads of ``diameter_m`` on a square grid; the struck bead
    {0, 0} in the middle of the left column (the lower middle for an even count)."""
    rows, columns = _grid_size(rows, columns)
    m, n = np.meshgrid(np.arange(rows) - (rows - 1) // 2, np.arange(columns), indexing="ij")
    labels = np.column_stack([m.ravel(), n.ravel()])
    return placed_packing(
        labels,
        labels[:, ::-1] * float(diameter_m),
        np.full(len(labels), float(diameter_m)),
        diameter_m,
        SQUARE_WALLS_DEG,
        f"square, {rows} x {columns}",
        struck,
        SQUARE_RAYS_DEG,
    )


def interstitial_fit_m(diameter_m: float) -> float:
    """The interstitial diameter that touches the four corner beads of a square cell of touching
    beads of ``diameter_m``: the cell's diagonal √2 d less one d, (√2 − 1) d."""
    return (math.sqrt(2.0) - 1.0) * float(diameter_m)


def centered_square(
    rows: int, columns: int, diameter_m: float, interstitial_diameter_m: float | None = None, struck=(0, 0)
) -> tuple[Packing, np.ndarray]:
    """(packing, interstitial bead indices): ``rows`` × ``columns`` corner beads of ``diameter_m``
    and one interstitial of ``interstitial_diameter_m`` (None: :func:`interstitial_fit_m`) in each
    of the (rows − 1)(columns − 1) cells."""
    rows, columns = _grid_size(rows, columns)
    small = interstitial_fit_m(diameter_m) if interstitial_diameter_m is None else float(interstitial_diameter_m)
    if not 0 < small:
        raise HexdemError(f"interstitial_diameter_m must be > 0, got {interstitial_diameter_m!r}")
    spacing = max(float(diameter_m), (float(diameter_m) + small) / math.sqrt(2.0))
    low = (rows - 1) // 2
    i, j = np.meshgrid(np.arange(rows) - low, np.arange(columns), indexing="ij")
    corners = np.column_stack([2 * i.ravel(), 2 * j.ravel()])
    ci, cj = np.meshgrid(np.arange(rows - 1) - low, np.arange(columns - 1), indexing="ij")
    centres = np.column_stack([2 * ci.ravel() + 1, 2 * cj.ravel() + 1])
    labels = np.vstack([corners, centres])
    diameters = np.concatenate([np.full(len(corners), float(diameter_m)), np.full(len(centres), small)])
    packing = placed_packing(
        labels,
        labels[:, ::-1] * spacing / 2,
        diameters,
        diameter_m,
        SQUARE_WALLS_DEG,
        f"centered-square, {rows} x {columns}",
        struck,
        SQUARE_RAYS_DEG,
    )
    return packing, np.arange(len(corners), len(labels))
