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
from hexdem.model.walls import CurvedWall, Wall, touching_walls


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

    Lines: ``label_lines``, each a :class:`LabelLine`, holds the beads from the start on, one label step at a time,
    until the packing ends;
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
        """{label: bead index}, made at the first lookup, not with every copy of the packing (building
        a model copies its packing; the cost: docs/validation/benchmarks.md, *Figures moved out of the
        docstrings*)."""
        return dict(zip(map(tuple, self.labels.tolist()), range(len(self.labels))))

    def index_of(self, m: int, n: int) -> int | None:
        """The bead index of label {m, n}, or None when it is not in the packing."""
        return self._lookup.get((m, n))

    def bonds(self) -> np.ndarray:
        """(B, 2) index pairs of touching neighbours read from the labels (:attr:`bond_steps`),
        each pair once; a packing without them finds its contacts from the geometry alone."""
        if not self.bond_steps:
            raise HexdemError(f"{self.shape} is not a triangular packing: its contacts come from the geometry")
        pairs = [
            (i, j)
            for i, (m, n) in enumerate(self.labels.tolist())
            for dm, dn in self.bond_steps
            if (j := self.index_of(m + dm, n + dn)) is not None
        ]
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
        moved = replace(
            self, positions_m=np.asarray(positions_m, float), diameters_m=np.asarray(diameters_m, float), walls=()
        )
        return replace(moved, walls=touching_walls(moved, [w.normal for w in self.walls]))


def unit_vector(angle_deg: float) -> np.ndarray:
    """(cos, sin) of ``angle_deg`` from +x."""
    angle = float(angle_deg)
    return np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle))])


def strike_direction(angle_deg: float) -> np.ndarray:
    """Unit vector of a strike at ``angle_deg`` from +x; it must point into the packing."""
    angle = float(angle_deg)
    if not np.isfinite(angle) or abs(angle) >= 90.0:
        raise HexdemError(
            f"strike angle {angle_deg}° does not point into the packing; use an angle in (-90°, 90°), e.g. 0 or 30"
        )
    return unit_vector(angle)
