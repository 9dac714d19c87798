"""A straight chain of touching beads, with intruders and dimers: the 1D granular crystal.

Bead k (label {0, k}) follows bead k − 1 along the chain's direction at ``angle_deg`` from +x,
touching it: the centres lie :math:`(d_{k−1} + d_k)/2` apart, so beads of other sizes (an intruder, a
dimer's alternating pair) keep the chain closed. Bead 0 is struck; the chain is free (no walls),
so its momentum and energy are conserved to the integrator's accuracy.
"""

from __future__ import annotations

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.packing import Packing, unit_vector
from hexdem.model.placed import placed_packing

#: The fewest beads of a chain: the struck one and one to pass the pulse to.
MIN_CHAIN_BEADS = 2


def chain_beads(beads) -> int:
    """``beads`` as the bead count of a chain, or a one-line HexdemError below :data:`MIN_CHAIN_BEADS`."""
    if int(beads) != beads or beads < MIN_CHAIN_BEADS:
        raise HexdemError(
            f"a chain needs beads >= {MIN_CHAIN_BEADS} (the struck one and one to pass the pulse to), got {beads}"
        )
    return int(beads)


def chain(beads: int, diameter_m: float, angle_deg: float = 0.0, diameters_m=(), struck=(0, 0)) -> Packing:
    """``beads`` touching beads along ``angle_deg``, each of ``diameter_m`` or of its own size in
    ``diameters_m`` (one per bead, or empty), struck at the bead labelled ``struck`` ({0, k}: bead k)."""
    beads = chain_beads(beads)
    sizes = np.full(beads, float(diameter_m)) if not len(diameters_m) else np.asarray(diameters_m, float)
    if sizes.shape != (beads,):
        raise HexdemError(f"diameters_m lists {len(sizes)} diameters for a chain of {beads} beads")
    centres = np.concatenate([[0.0], np.cumsum((sizes[:-1] + sizes[1:]) / 2)])
    positions = centres[:, None] * unit_vector(angle_deg)[None, :]
    labels = np.column_stack([np.zeros(beads, dtype=int), np.arange(beads)])
    return placed_packing(labels, positions, sizes, diameter_m, (), f"chain, {beads} beads", struck, (angle_deg,))
