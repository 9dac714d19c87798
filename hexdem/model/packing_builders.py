"""The packing a configuration describes, built by its shape's builder.

The triangular shapes (``hexagon``, ``half-hexagon``, ``half-disc``, ``triangle``,
``parallelogram``, ``disc``, ``sites``) place beads on the paper's lattice
(:mod:`hexdem.model.lattice`, :mod:`hexdem.model.sites`). The others place them themselves:

* ``square`` (``rows``, ``columns``) and ``centered-square`` (also ``interstitial_diameter_m``,
  None: the size that touches the four corners, and ``interstitial_material``, None: the beads'),
  in a square basin (:mod:`hexdem.model.square_crystals`);
* ``chain`` (``beads`` along ``angle_deg``, with optional per-bead ``diameters_m`` and, when
  ``materials`` is a list, per-bead material names: intruders and dimers), free
  (:mod:`hexdem.model.chain`);
* ``packing``: the measured positions of ``packing_file``, struck at row ``struck_bead``, with
  ``walls`` ``"none"`` or ``"hull"`` (:mod:`hexdem.model.packing_file`);
* ``random``: a disordered polydisperse disc (``radius_m``, ``diameter_spread``, ``seed``), whose
  positions a LAMMPS compaction makes first (:mod:`hexdem.experiments.random_packing`); it is
  then built as the ``packing`` of those positions.

A builder that gives some beads another material hands them over as material regions, which
go before the configuration's own ``regions`` (:mod:`hexdem.model.regions`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.chain import chain
from hexdem.model.lattice import (Lattice, disc, half_disc, half_hexagon, hexagon, parallelogram, strike_direction,
                                  triangle)
from hexdem.model.packing_file import packing_from_file, read_packing_rows
from hexdem.model.sites import read_sites
from hexdem.model.square_crystals import centered_square, square

TRIANGULAR_SHAPES = ("hexagon", "half-hexagon", "half-disc", "triangle", "parallelogram", "disc", "sites")
PLACED_SHAPES = ("square", "centered-square", "chain", "packing")
#: Placed crystals whose pulse runs along straight chains of touching beads, as a solitary wave
#: (their default duration: :func:`~hexdem.model.timescale.solitary_crossing_time_s`).
CHAIN_SHAPES = ("square", "centered-square", "chain")
#: Shapes whose positions a LAMMPS run makes (:mod:`hexdem.experiments.random_packing`); they are
#: built as the ``packing`` of that run's positions.
PREPARED_SHAPES = ("random",)
SHAPES = TRIANGULAR_SHAPES + PLACED_SHAPES + PREPARED_SHAPES


@dataclass(frozen=True)
class BuiltPacking:
    """A shape's packing and the material ``regions`` its builder sets (tables {material, sites})."""

    lattice: Lattice
    regions: tuple = ()


def material_regions(lattice: Lattice, names) -> tuple:
    """Regions {material, sites} giving each bead of ``lattice`` its name in ``names`` (one per
    bead; an empty name keeps the beads' material)."""
    names = np.asarray(names, dtype=object)
    return tuple({"material": str(name), "sites": tuple(tuple(int(v) for v in label)
                                                         for label in lattice.indices[names == name])}
                 for name in dict.fromkeys(names.tolist()) if name)


def _chain(config, struck) -> BuiltPacking:
    lattice = chain(config.beads, config.diameter_m, config.angle_deg, config.diameters_m, struck)
    if isinstance(config.materials, dict):
        return BuiltPacking(lattice)
    if len(config.materials) != len(lattice):
        raise HexdemError(f"materials lists {len(config.materials)} names for a chain of {len(lattice)} beads")
    return BuiltPacking(lattice, material_regions(lattice, config.materials))


def _centered_square(config, struck) -> BuiltPacking:
    lattice, interstitials = centered_square(config.rows, config.columns, config.diameter_m,
                                             config.interstitial_diameter_m, struck)
    if config.interstitial_material is None:
        return BuiltPacking(lattice)
    names = np.full(len(lattice), "", dtype=object)
    names[interstitials] = config.interstitial_material
    return BuiltPacking(lattice, material_regions(lattice, names))


def _packing_file(config) -> BuiltPacking:
    if config.packing_file is None:
        raise HexdemError('shape = "packing" needs packing_file = "beads.csv" (header x,y,diameter[,material])')
    beads = read_packing_rows(config.packing_file)
    lattice = packing_from_file(config.packing_file, beads, config.diameter_m, config.struck_bead, config.walls,
                                strike_direction(config.strike_angle_deg))
    return BuiltPacking(lattice, material_regions(lattice, beads.materials))


def build_packing(config, struck) -> BuiltPacking:
    """The packing of ``config``'s ``shape`` (a :class:`~hexdem.model.config.RunConfig`), struck
    at the bead labelled ``struck`` (a packing file: at its ``struck_bead``)."""
    builders = {
        "hexagon": lambda: BuiltPacking(hexagon(config.edge_beads, config.diameter_m, struck)),
        "half-hexagon": lambda: BuiltPacking(half_hexagon(config.long_edge, config.short_edge, config.diameter_m,
                                                          struck)),
        "half-disc": lambda: BuiltPacking(half_disc(config.radius_beads, config.diameter_m, struck)),
        "triangle": lambda: BuiltPacking(triangle(config.edge_beads, config.diameter_m, struck)),
        "disc": lambda: BuiltPacking(disc(config.radius_beads, config.diameter_m, struck)),
        "parallelogram": lambda: BuiltPacking(parallelogram(
            config.edge_beads, config.edge_beads if config.depth_beads is None else config.depth_beads,
            config.diameter_m, struck)),
        "sites": lambda: BuiltPacking(read_sites(config.sites, config.sites_file, config.diameter_m,
                                                 config.site_walls_deg, struck)),
        "square": lambda: BuiltPacking(square(config.rows, config.columns, config.diameter_m, struck)),
        "centered-square": lambda: _centered_square(config, struck),
        "chain": lambda: _chain(config, struck),
        "packing": lambda: _packing_file(config),
    }
    if config.shape != "sites" and (config.sites or config.sites_file or config.site_walls_deg):
        raise HexdemError(f"sites, sites_file and site_walls_deg describe shape = \"sites\", not {config.shape!r}")
    if config.shape != "packing" and config.packing_file is not None:
        raise HexdemError(f"packing_file describes shape = \"packing\", not {config.shape!r}")
    if config.shape in PREPARED_SHAPES:
        raise HexdemError(f"shape = {config.shape!r} is packed by a LAMMPS compaction before it is built: "
                          "hexdem run, compare and sweep prepare it (hexdem.experiments.random_packing)")
    return builders[config.shape]()
