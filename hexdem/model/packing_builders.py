"""The packing a configuration describes, built by its shape's builder.

The triangular shapes (``hexagon``, ``half-hexagon``, ``half-disc``, ``triangle``,
``parallelogram``, ``disc``, ``sites``) place beads on the paper's lattice
(:mod:`hexdem.model.triangular`, :mod:`hexdem.model.sites`). The others place them themselves:

* ``square`` (``rows``, ``columns``) and ``centered-square`` (also ``interstitial_diameter_m``,
  None: the size that touches the four corners, and ``interstitial_material``, None: the beads'),
  in a square basin (:mod:`hexdem.model.square_crystals`);
* ``chain`` (``beads`` along ``angle_deg``, with ``diameters_m`` and ``bead_materials`` one per
  bead or a pattern that repeats (a dimer: two), and ``intruders``, beads of their own size or
  material), free (:mod:`hexdem.model.chain`);
* ``packing``: the measured positions of ``packing_file``, struck at row ``struck_bead``, with
  ``walls`` ``"none"`` or ``"hull"`` (:mod:`hexdem.model.packing_file`);
* ``random``: a disordered polydisperse disc (``radius_m``, ``diameter_spread``, ``seed``), whose
  positions a LAMMPS compaction makes first (:mod:`hexdem.experiments.random_packing`); it is
  then built as the ``packing`` of those positions.

A builder that gives some beads another material hands them over as material regions, which
go before the configuration's own ``regions`` (:mod:`hexdem.model.regions`).

A key that describes some shapes only (:data:`SHAPE_KEYS`) is refused on any other, so that no
key is silently ignored (:func:`check_shape_keys`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypedDict

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.chain import chain, chain_beads
from hexdem.model.packing import Packing, strike_direction
from hexdem.model.packing_file import packing_from_file, read_packing_rows
from hexdem.model.sites import read_sites
from hexdem.model.square_crystals import centered_square, square
from hexdem.model.triangular import disc, half_disc, half_hexagon, hexagon, parallelogram, triangle

TRIANGULAR_SHAPES = ("hexagon", "half-hexagon", "half-disc", "triangle", "parallelogram", "disc", "sites")
PLACED_SHAPES = ("square", "centered-square", "chain", "packing")
#: Walled crystals whose pulse runs along straight rows of touching beads, as a solitary wave that
#: the far wall sends back undiminished (their default duration ends before it returns:
#: :func:`~hexdem.model.timescale.solitary_crossing_time_s`). A chain has no walls: its far end
#: flies off and nothing comes back, so it keeps the generous layer-by-layer duration, which
#: also lets a dimer chain's slower pulse arrive.
ROW_CRYSTAL_SHAPES = ("square", "centered-square")
#: Shapes whose positions a LAMMPS run makes (:mod:`hexdem.experiments.random_packing`); they are
#: built as the ``packing`` of that run's positions.
PREPARED_SHAPES = ("random",)
SHAPES = TRIANGULAR_SHAPES + PLACED_SHAPES + PREPARED_SHAPES
#: The keys that describe some shapes only, and those shapes; every other key applies to every
#: shape. ``lines`` follow the triangular lattice's directions (the other shapes' lines are their
#: rays); a random disc's struck bead is found on its edge; a chain has no walls.
SHAPE_KEYS = {
    "edge_beads": ("hexagon", "triangle", "parallelogram"),
    "long_edge": ("half-hexagon",),
    "short_edge": ("half-hexagon",),
    "radius_beads": ("half-disc", "disc"),
    "depth_beads": ("parallelogram",),
    "sites": ("sites",),
    "sites_file": ("sites",),
    "site_walls_deg": ("sites",),
    "lines": TRIANGULAR_SHAPES,
    "rows": ("square", "centered-square"),
    "columns": ("square", "centered-square"),
    "interstitial_diameter_m": ("centered-square",),
    "interstitial_material": ("centered-square",),
    "beads": ("chain",),
    "angle_deg": ("chain",),
    "diameters_m": ("chain",),
    "bead_materials": ("chain",),
    "intruders": ("chain",),
    "packing_file": ("packing",),
    "struck_bead": ("packing",),
    "walls": ("packing", "random"),
    "radius_m": ("random",),
    "diameter_spread": ("random",),
    "seed": ("random",),
    **dict.fromkeys(
        ("wall_material", "wall_restitution", "wall_friction"), tuple(shape for shape in SHAPES if shape != "chain")
    ),
}


class IntruderTable(TypedDict, total=False):
    """A chain's intruder: its ``bead`` (from 0, the struck one) and its own ``diameter_m`` [m]
    and/or ``material`` (checked by :class:`~hexdem.model.config.RunConfig`)."""

    bead: int
    diameter_m: float
    material: str


def check_shape_keys(config) -> None:
    """Refuse a key of :data:`SHAPE_KEYS` set (written by the user whatever its value, or
    different from its default: :meth:`~hexdem.model.config.RunConfig.set_keys`) on a shape it
    does not describe, in one line naming the key and the shape."""
    for key in config.set_keys():
        shapes = SHAPE_KEYS.get(key, (config.shape,))
        if config.shape not in shapes:
            named = " or ".join(", ".join(f'"{shape}"' for shape in shapes).rsplit(", ", 1))
            raise HexdemError(f"{key} describes shape = {named}, not {config.shape!r}: remove it or change the shape")


@dataclass(frozen=True)
class BuiltPacking:
    """A shape's packing and the material ``regions`` its builder sets (tables {material, sites})."""

    packing: Packing
    regions: tuple = ()


def material_regions(packing: Packing, names) -> tuple:
    """Regions {material, sites} giving each bead of ``packing`` its name in ``names`` (one per
    bead; an empty name keeps the beads' material)."""
    names = np.asarray(names, dtype=object)
    return tuple(
        {"material": str(name), "sites": tuple(tuple(int(v) for v in label) for label in packing.labels[names == name])}
        for name in dict.fromkeys(names.tolist())
        if name
    )


def per_bead(values, fill, beads: int, key: str, what: str) -> list:
    """One value per bead of a chain of ``beads``: ``fill`` for each when ``values`` is empty,
    ``values`` itself when it lists one per bead, or repeated from bead 0 when its length divides
    ``beads`` (a dimer: two). ``key`` names ``values`` and ``what`` its items in an error."""
    if not values:
        return [fill] * beads
    if beads % len(values):
        raise HexdemError(
            f"{key} lists {len(values)} {what} for a chain of {beads} beads: list one per bead, or a "
            "pattern that repeats, whose length divides beads"
        )
    return list(values) * (beads // len(values))


def _chain(config, struck) -> BuiltPacking:
    beads = chain_beads(config.beads)
    sizes = per_bead(config.diameters_m, config.diameter_m, beads, "diameters_m", "diameters")
    names = per_bead(config.bead_materials, "", beads, "bead_materials", "names")
    for k, intruder in enumerate(config.intruders):
        bead = intruder.get("bead")
        if bead is None or not 0 <= bead < beads or not {"diameter_m", "material"} & set(intruder):
            raise HexdemError(
                f"intruders.{k} must be a table {{bead = k, diameter_m = ..., material = ...}} with "
                f"bead from 0 to {beads - 1} and a diameter_m or a material, got {intruder!r}"
            )
        sizes[bead] = intruder.get("diameter_m", sizes[bead])
        names[bead] = intruder.get("material", names[bead])
    packing = chain(beads, config.diameter_m, config.angle_deg, sizes, struck)
    return BuiltPacking(packing, material_regions(packing, names))


def _centered_square(config, struck) -> BuiltPacking:
    packing, interstitials = centered_square(
        config.rows, config.columns, config.diameter_m, config.interstitial_diameter_m, struck
    )
    if config.interstitial_material is None:
        return BuiltPacking(packing)
    names = np.full(len(packing), "", dtype=object)
    names[interstitials] = config.interstitial_material
    return BuiltPacking(packing, material_regions(packing, names))


def _packing_file(config) -> BuiltPacking:
    if config.packing_file is None:
        raise HexdemError('shape = "packing" needs packing_file = "beads.csv" (header x,y,diameter[,material])')
    beads = read_packing_rows(config.packing_file)
    packing = packing_from_file(
        config.packing_file,
        beads,
        config.diameter_m,
        config.struck_bead,
        config.walls,
        strike_direction(config.strike_direction_deg),
    )
    return BuiltPacking(packing, material_regions(packing, beads.materials))


def shape_packing(config, struck) -> BuiltPacking:
    """The packing of ``config``'s ``shape`` (a :class:`~hexdem.model.config.RunConfig`), struck
    at the bead labelled ``struck`` (a packing file: at its ``struck_bead``)."""
    builders = {
        "hexagon": lambda: BuiltPacking(hexagon(config.edge_beads, config.diameter_m, struck)),
        "half-hexagon": lambda: BuiltPacking(
            half_hexagon(config.long_edge, config.short_edge, config.diameter_m, struck)
        ),
        "half-disc": lambda: BuiltPacking(half_disc(config.radius_beads, config.diameter_m, struck)),
        "triangle": lambda: BuiltPacking(triangle(config.edge_beads, config.diameter_m, struck)),
        "disc": lambda: BuiltPacking(disc(config.radius_beads, config.diameter_m, struck)),
        "parallelogram": lambda: BuiltPacking(
            parallelogram(
                config.edge_beads,
                config.edge_beads if config.depth_beads is None else config.depth_beads,
                config.diameter_m,
                struck,
            )
        ),
        "sites": lambda: BuiltPacking(
            read_sites(config.sites, config.sites_file, config.diameter_m, config.site_walls_deg, struck)
        ),
        "square": lambda: BuiltPacking(square(config.rows, config.columns, config.diameter_m, struck)),
        "centered-square": lambda: _centered_square(config, struck),
        "chain": lambda: _chain(config, struck),
        "packing": lambda: _packing_file(config),
    }
    if config.shape in PREPARED_SHAPES:
        raise HexdemError(
            f"shape = {config.shape!r} is packed by a LAMMPS compaction before it is built: "
            "hexdem run, compare and sweep prepare it (hexdem.experiments.random_packing)"
        )
    return builders[config.shape]()
