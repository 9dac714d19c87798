"""A dense, polydisperse, disordered disc of beads (``shape = "random"``): its beads and their
loose start.

The beads' diameters are drawn uniformly from d (1 ± s), s = ``diameter_spread`` (a spread of
about 10 % or more keeps a 2D packing from crystallizing), by NumPy's default generator seeded
with ``seed``, until their area fills :data:`DENSE_FRACTION` of the disc of ``radius_m``. They
start spread out at random (random sequential addition, larger beads first) in a wider disc
whose area they fill to :data:`LOOSE_FRACTION`. A LAMMPS compaction then packs them
(:mod:`hexdem.experiments.random_packing`): the positions come out of the packing's own
dynamics, not from any lattice. The same ``seed`` gives the same packing.
"""

from __future__ import annotations

import math

import numpy as np

from hexdem.errors import HexdemError

#: Area fraction that sizes the bead count: a disordered 2D packing of discs jams near 0.84;
#: this leaves room for its rattlers and its rough rim.
DENSE_FRACTION = 0.80
#: Area fraction of the loose start, well below the 0.547 at which random sequential addition
#: of discs jams, so that placing every bead takes few tries.
LOOSE_FRACTION = 0.35
#: Largest ``diameter_spread``: d (1 ± s) must stay positive and within the factor 2 that a
#: packing's diameters may span around ``diameter_m``.
MAX_SPREAD = 0.5
#: Smallest ``radius_m``, in bead diameters: the disc holds a middle bead and the ring of six
#: that holds it from every side against the compaction's pull to the centre (ring centres one
#: diameter out, their far edges at 1.5 d), some 7 beads. A disc of one diameter (4 beads) left its
#: middle bead in a cage of three and did not settle in 2,000,000 steps (seed 0); at 1.5 d, the
#: discs of seeds 0 to 7 (7 or 8 beads) settled, and at 1.73 d and 2 d those of seeds 0 to 5.
MIN_RADIUS_D = 1.5
#: Random tries per bead before the loose start is given up.
MAX_TRIES = 10_000
#: A loose bead keeps this gap to every other, as a fraction of their mean diameter.
LOOSE_GAP = 0.02


def check_random_disc(radius_m: float, diameter_m: float, spread: float, seed: int) -> None:
    """Refuse parameters that make no random disc, in one line."""
    if not 0 <= spread < MAX_SPREAD:
        raise HexdemError(
            f"diameter_spread must be at least 0 and below {MAX_SPREAD:g} (diameters d (1 ± s)), got {spread!r}"
        )
    if not radius_m >= MIN_RADIUS_D * diameter_m:
        raise HexdemError(
            f"radius_m must be at least {MIN_RADIUS_D:g} diameter_m = {MIN_RADIUS_D * diameter_m:g} m "
            f"for a random disc (a middle bead and the ring of six that holds it), got {radius_m!r}"
        )
    if seed < 0:
        raise HexdemError(f"seed must be an integer >= 0, got {seed!r}")


def random_diameters(radius_m: float, diameter_m: float, spread: float, seed: int) -> np.ndarray:
    """The beads' diameters [m]: uniform in d (1 ± ``spread``), drawn until they cover
    :data:`DENSE_FRACTION` of the disc of ``radius_m``; at least 2 beads."""
    rng = np.random.default_rng(int(seed))
    target, diameters, area = DENSE_FRACTION * math.pi * radius_m**2, [], 0.0
    while area < target or len(diameters) < 2:
        d = diameter_m * (1 + spread * rng.uniform(-1.0, 1.0))
        diameters.append(d)
        area += math.pi * d * d / 4
    return np.array(diameters)


def loose_positions(diameters_m, seed: int) -> np.ndarray:
    """(N, 2) centres [m] of beads of ``diameters_m`` placed one by one, larger first, at random
    points of a disc about the origin that they fill to :data:`LOOSE_FRACTION`, each keeping a
    gap of :data:`LOOSE_GAP` mean diameters to the others."""
    diameters = np.asarray(diameters_m, float)
    rng = np.random.default_rng([int(seed), 1])
    radius = math.sqrt(float(np.sum(diameters**2)) / 4 / LOOSE_FRACTION)
    positions = np.full((len(diameters), 2), np.nan)
    for k in np.argsort(-diameters, kind="stable"):
        reach = radius - diameters[k] / 2
        for _ in range(MAX_TRIES):
            r, phi = reach * math.sqrt(rng.uniform()), rng.uniform(0.0, 2 * math.pi)
            point = np.array([r * math.cos(phi), r * math.sin(phi)])
            placed = ~np.isnan(positions[:, 0])
            distance = np.linalg.norm(positions[placed] - point, axis=1)
            if np.all(distance >= (1 + LOOSE_GAP) * (diameters[placed] + diameters[k]) / 2):
                positions[k] = point
                break
        else:
            raise HexdemError(f"no room for bead {k} of the random disc's loose start after {MAX_TRIES} tries")
    return positions


def edge_bead(positions_m, diameters_m, direction) -> int:
    """The bead in the middle of the edge that a strike along the unit vector ``direction``
    meets: of the exposed beads (nothing lies in the way of a striker coming along
    ``direction``), the one closest to the line along ``direction`` through the centroid."""
    positions, radii = np.asarray(positions_m, float), np.asarray(diameters_m, float) / 2
    direction = np.asarray(direction, float)
    normal = np.array([-direction[1], direction[0]])
    relative = positions - positions.mean(axis=0)
    for i in np.argsort(np.abs(relative @ normal), kind="stable"):
        ahead = (positions - positions[i]) @ -direction  # how far before bead i along the striker's way
        beside = np.abs((positions - positions[i]) @ normal)
        blocking = (ahead > 0) & (beside < radii + radii[i])
        blocking[i] = False
        if not blocking.any():
            return int(i)
    raise HexdemError("no bead of the packing is exposed to the strike")
