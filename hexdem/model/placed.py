"""A packing from placed beads: labels, positions and diameters given, walls found from them.

The triangular shapes place their beads on the paper's lattice (:func:`~hexdem.model.triangular.from_sites`);
every other builder (square and centered-square crystals, chains, measured positions) places them
itself and calls :func:`placed_packing`, which checks them, finds the struck bead by its label
and puts flat walls touching the packing. Contacts are not stored: both engines find them from
the geometry (beads touch when their gap is below zero).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.packing import Packing, unit_vector
from hexdem.model.walls import touching_walls

#: Beads may overlap by at most this fraction of the smaller diameter at rest (round-off of
#: measured or computed positions); more is a packing that would explode.
MAX_REST_OVERLAP = 1e-6
#: A placed bead's diameter lies within this factor of the nominal ``diameter_m``, which sets the
#: units and, with the smallest bead's contact, the time step: a bead 10 times smaller has a
#: contact about 10 times shorter, and one 1e30 times larger is a typing error.
MAX_DIAMETER_RATIO = 10.0
#: Beads may spread over at most this many times their length laid end to end (a chain spans
#: just under 1; a packing with gaps more): farther is a typing error, not a packing.
MAX_SPAN_FACTOR = 10.0


def check_no_overlap(positions_m, diameters_m, what: str) -> None:
    """Refuse beads that overlap at rest by more than :data:`MAX_REST_OVERLAP` of the smaller one."""
    from scipy.spatial import cKDTree

    positions, diameters = np.asarray(positions_m, float), np.asarray(diameters_m, float)
    pairs = cKDTree(positions).query_pairs(float(diameters.max()), output_type="ndarray")
    if not len(pairs):
        return
    i, j = pairs.T
    overlap = (diameters[i] + diameters[j]) / 2 - np.linalg.norm(positions[j] - positions[i], axis=1)
    worst = int(np.argmax(overlap / np.minimum(diameters[i], diameters[j])))
    if overlap[worst] > MAX_REST_OVERLAP * min(diameters[i[worst]], diameters[j[worst]]):
        raise HexdemError(
            f"{what}: beads {i[worst]} and {j[worst]} overlap by {overlap[worst]:.3g} m at rest; "
            f"a packing's beads may touch but not overlap (by {MAX_REST_OVERLAP:g} of the smaller "
            "diameter at most: write positions with every digit, as repr or %.17g do)"
        )


def check_extent(positions_m, diameters_m, what: str) -> None:
    """Refuse beads spread over more than :data:`MAX_SPAN_FACTOR` times the length of all of them
    laid end to end (the diagonal of their bounding box against the sum of their diameters): a
    position in other units than metres, or a bead far from the rest, which no pulse could reach."""
    span = float(np.hypot(*np.ptp(positions_m, axis=0)))
    reach = MAX_SPAN_FACTOR * float(np.sum(diameters_m))
    if not span <= reach:
        raise HexdemError(
            f"{what}: the beads span {span:.3g} m, more than {MAX_SPAN_FACTOR:g} times all "
            f"{len(diameters_m)} of them laid end to end ({reach:.3g} m); positions are in metres, "
            "and a pulse crosses only beads that touch"
        )


def placed_packing(
    labels, positions_m, diameters_m, diameter_m: float, wall_angles_deg, shape: str, struck, rays_deg
) -> Packing:
    """The packing of beads labelled ``labels`` (N, 2) int at ``positions_m`` (N, 2) [m] with
    ``diameters_m`` (N,) [m] (nominal ``diameter_m``), struck at the bead labelled ``struck``,
    inside flat walls touching it whose inward normals point at ``wall_angles_deg`` (the one at
    0° has the struck bead's hole), its lines the rays at ``rays_deg``."""
    labels = np.asarray(labels, dtype=int).reshape(-1, 2)
    positions, diameters = np.asarray(positions_m, float).reshape(-1, 2), np.asarray(diameters_m, float)
    if not len(labels):
        raise HexdemError(f"{shape}: a packing needs at least 1 bead, got none")
    if not (np.all(np.isfinite(positions)) and np.all(diameters > 0) and len(diameters) == len(labels)):
        raise HexdemError(f"{shape}: every bead needs a finite position and a diameter > 0")
    ratio = diameters / float(diameter_m)
    if not (ratio.min() >= 1 / MAX_DIAMETER_RATIO and ratio.max() <= MAX_DIAMETER_RATIO):
        raise HexdemError(
            f"{shape}: diameters {diameters.min():.4g} to {diameters.max():.4g} m are not within a factor "
            f"{MAX_DIAMETER_RATIO:g} of diameter_m = {float(diameter_m):g} m"
        )
    check_extent(positions, diameters, shape)
    check_no_overlap(positions, diameters, shape)
    hit = np.flatnonzero(np.all(labels == np.asarray(struck, dtype=int), axis=1))
    if not len(hit):
        raise HexdemError(f"{shape}: the struck bead {tuple(int(v) for v in struck)} is not in the packing")
    packing = Packing(
        labels=labels,
        positions_m=positions,
        diameters_m=diameters,
        diameter_m=float(diameter_m),
        struck=int(hit[0]),
        walls=(),
        shape=shape,
        rays_deg=tuple(float(a) for a in rays_deg),
    )
    return replace(packing, walls=touching_walls(packing, [unit_vector(a) for a in wall_angles_deg]))
