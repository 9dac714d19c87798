"""Material regions of a packing: interfaces, strips and intruders as data (per-bead material ids).

A region is a table ``{material = NAME, sites = [[m, n], ...], x_min_d = …, x_max_d = …,
y_min_d = …, y_max_d = …}``: the beads it selects (those listed, and within every bound given,
measured from the struck bead in nominal diameters d) take that material. Regions apply in
order, a later one over an earlier. A half-plane interface is one bound (``x_min_d = 10``), a
strip two, intruders a list of sites (Leonard et al., PRE 86, 031305; Tichler et al., PRL 2013).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TypedDict

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.materials import Material
from hexdem.model.packing import Packing


class RegionTable(TypedDict, total=False):
    """A region's keys and their types (checked by :class:`~hexdem.model.config.RunConfig`)."""

    material: str
    sites: tuple[tuple[int, int], ...]
    x_min_d: float
    x_max_d: float
    y_min_d: float
    y_max_d: float


#: A region's bounds: key → (coordinate, whether it is a lower bound).
BOUNDS = {"x_min_d": (0, True), "x_max_d": (0, False), "y_min_d": (1, True), "y_max_d": (1, False)}
KEYS = set(RegionTable.__annotations__)


def _selected(packing: Packing, region: dict, k: int) -> np.ndarray:
    """(N,) bool: the beads region ``k`` selects."""
    unknown = sorted(set(region) - KEYS)
    if unknown or "material" not in region:
        raise HexdemError(
            f"region {k}: "
            + (f"unknown key(s) {', '.join(unknown)}; " if unknown else "")
            + f"a region is material = NAME with sites and/or {', '.join(BOUNDS)}"
        )
    if not set(region) - {"material"}:
        raise HexdemError(f"region {k} selects nothing: give sites = [[m, n], ...] and/or {', '.join(BOUNDS)}")
    chosen = np.ones(len(packing), dtype=bool)
    if "sites" in region:
        sites = region["sites"]
        missing = [tuple(s) for s in sites if packing.index_of(*s) is None]
        if missing:
            raise HexdemError(f"region {k}: site {{{missing[0][0]}, {missing[0][1]}}} is not in the packing")
        listed = np.zeros(len(packing), dtype=bool)
        listed[[packing.index_of(*s) for s in sites]] = True
        chosen &= listed
    relative = (packing.positions_m - packing.positions_m[packing.struck]) / packing.diameter_m
    for key, (axis, lower) in BOUNDS.items():
        if key in region:
            value = region[key]
            chosen &= relative[:, axis] >= value - 1e-9 if lower else relative[:, axis] <= value + 1e-9
    if not chosen.any():
        raise HexdemError(f"region {k} ({region['material']}) selects no bead of the packing")
    return chosen


def assign_materials(packing: Packing, regions, bead: Material, lookup) -> tuple[Packing, tuple[Material, ...]]:
    """``packing`` with the material ids the ``regions`` give, and the materials beyond ``bead``
    by id (1, 2, …, in order of first use); ``lookup(name)`` finds a material by name."""
    extra: list[Material] = []
    ids = packing.material_ids.copy()
    for k, region in enumerate(regions):
        chosen = _selected(packing, region, k)
        material = lookup(region["material"])
        if material != bead and material not in extra:
            extra.append(material)
        ids[chosen] = 0 if material == bead else 1 + extra.index(material)
    used = [m for i, m in enumerate(extra) if np.any(ids == i + 1)]
    renumber = {extra.index(m) + 1: k + 1 for k, m in enumerate(used)}
    table = np.arange(len(extra) + 1)
    table[list(renumber)] = list(renumber.values())
    ids = table[ids]
    return replace(packing, material_ids=ids), tuple(used)
