"""Observation lines of any packing: rays from the struck bead.

On a packing that is not the triangular lattice, a line is a ray from the struck bead at an
angle from +x, the 0° strike direction (the inward normal of the struck edge): it holds the beads
whose centres lie within :data:`RAY_HALF_WIDTH_D` bead diameters of the ray, ahead of the struck
bead, ordered by their distance from it; the struck bead is bead 0 of every ray. A line's name
is its angle, signed: ``"0"``, ``"+45"``, ``"-45"``, ``"+90"``. On the triangular lattice the
paper's ``"0"``, ``"+30"`` and ``"-30"`` are these same rays, and keep their lattice definition
(:meth:`~hexdem.model.packing.Packing.line`).
"""

from __future__ import annotations

import numpy as np

#: A bead is on a ray when its centre lies within this many nominal diameters of it: the
#: neighbouring rows of a square packing lie d away, a centered-square's interstitials d/2.
RAY_HALF_WIDTH_D = 0.25


def ray_name(angle_deg: float) -> str:
    """The name of the ray at ``angle_deg`` from +x: ``"0"``, ``"+45"``, ``"-90"``, ``"+22.5"``."""
    return "0" if angle_deg == 0 else f"{angle_deg:+g}"


def ray_beads(positions_m, origin: int, angle_deg: float, diameter_m: float) -> np.ndarray:
    """Bead indices on the ray from bead ``origin`` at ``angle_deg`` from +x, nearest first
    (``origin`` itself first): centres within :data:`RAY_HALF_WIDTH_D` ``diameter_m`` of the ray."""
    positions = np.asarray(positions_m, float)
    direction = np.array([np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))])
    offsets = positions - positions[origin]
    along = offsets @ direction
    across = np.abs(offsets @ np.array([-direction[1], direction[0]]))
    on = np.flatnonzero((across <= RAY_HALF_WIDTH_D * diameter_m) & (along >= 0.0))
    return on[np.lexsort((on != origin, along[on]))]
