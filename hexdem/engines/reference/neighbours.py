"""The reference engine's neighbour search: which pairs of bodies may touch, found from their positions.

Kept apart from the forces (as JAX-MD keeps ``partition`` apart from its energies): the kernels
take the list as an argument and never know how it was found. Lengths are in the run's length
unit (m in SI, d in the paper's units).

* **Contact.** Two bodies touch when their gap r_ij − R_i − R_j is below 0 (the tolerance is zero,
  as in LAMMPS's granular pair styles): a listed pair with a positive gap feels no force.
* **Verlet list.** The list holds every pair whose gap is below the skin at its build: the pairs
  that :meth:`scipy.spatial.cKDTree.query_pairs` finds within the largest contact distance plus
  the skin, kept where r_ij < R_i + R_j + skin. A pair that no longer touches stays listed until
  the next build; a pair that comes to touch is listed before it does.
* **Skin** :data:`SKIN_DIAMETERS` times the smallest diameter, the skin of the LAMMPS deck
  (``neighbor 0.1 d bin``). Below the next-nearest gap of a triangular packing ((√3 − 1) d), so
  that such a packing's list is exactly its touching pairs; a body moves half of it, 0.05 d,
  in 2.4 ms at 0.4 m/s and d = 19.05 mm, longer than most runs.
* **Rebuild** when any body has moved more than :data:`REBUILD_SHARE` of the skin since the build
  (LAMMPS's ``neigh_modify check yes``): two bodies then have closed their gap by at most the
  skin, so no contact can have been missed. The kernels check it before every step and stop
  there for the engine to rebuild.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

#: The skin in units of the smallest body diameter.
SKIN_DIAMETERS = 0.1
#: The list is rebuilt once a body has moved this share of the skin from where it was at the build.
REBUILD_SHARE = 0.5


def skin_of(diameters) -> float:
    """The skin of bodies of ``diameters`` (in their unit): :data:`SKIN_DIAMETERS` times the smallest."""
    return SKIN_DIAMETERS * float(np.min(diameters))


def candidate_pairs(positions, radii, skin: float) -> np.ndarray:
    """(P, 2) the pairs (i < j) of bodies at ``positions`` (N, 2) with ``radii`` (N,) whose gap is
    below ``skin``, sorted by i, then j (so that the kernels run through memory in order)."""
    positions, radii = np.asarray(positions, float), np.asarray(radii, float)
    if len(radii) < 2:
        return np.zeros((0, 2), dtype=np.int64)
    near = cKDTree(positions).query_pairs(2.0 * radii.max() + skin, output_type="ndarray")
    i, j = near[:, 0], near[:, 1]
    distance = np.linalg.norm(positions[j] - positions[i], axis=1)
    near = near[distance < radii[i] + radii[j] + skin]
    return near[np.lexsort((near[:, 1], near[:, 0]))].astype(np.int64)


def carried_over(old_pairs, values, new_pairs) -> np.ndarray:
    """(P_new,) the per-pair ``values`` of the list ``old_pairs`` moved to the list ``new_pairs``
    by their (i, j) key (both lists sorted as :func:`candidate_pairs` sorts them); 0 for a pair new
    to the list. A contact's history survives a rebuild this way; a pair that leaves the list has
    long stopped touching (it is further apart than the skin), so its history is lost, as in LAMMPS."""
    old_pairs, new_pairs = np.asarray(old_pairs, np.int64), np.asarray(new_pairs, np.int64)
    carried = np.zeros(len(new_pairs))
    if not len(old_pairs) or not len(new_pairs):
        return carried
    size = int(max(old_pairs.max(), new_pairs.max())) + 1
    old_keys, new_keys = old_pairs[:, 0] * size + old_pairs[:, 1], new_pairs[:, 0] * size + new_pairs[:, 1]
    at = np.minimum(np.searchsorted(old_keys, new_keys), len(old_keys) - 1)
    found = old_keys[at] == new_keys
    carried[found] = np.asarray(values, float)[at[found]]
    return carried
