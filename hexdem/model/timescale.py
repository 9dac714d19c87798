"""The natural time scale of an impact: the shortest Hertz contact time among the pairs it sets
moving, from which the time step and the sampling follow (see
:meth:`~hexdem.model.config.RunConfig.contact_time_s`).

Two spheres meeting at relative speed V touch for t_c = 2.9432 (μ²/(A² V))^{1/5}
(:func:`~hexdem.model.hertz.contact_time`, μ the reduced mass, A = k_n sqrt(R_eff)). With one
material the pair is two equal beads; unlike beads and strikers of their own material or size
add their pairs, and a precompressed packing its linearized contact's half period.

The contact is shortest at the fastest approach, as V^(-1/5). An impact sets one body moving
at V0 against bodies at rest; an initial state may set any bodies moving, and the fastest
approach it can make is the largest relative speed |v_i − v_j| of two of its bodies, or of one
against the walls at rest (:func:`fastest_approach_m_s`): a bead given 100 V0 needs a
step 100^(1/5) = 2.5 times shorter. A speed at which two bodies meeting head on would press
into each other by half the smaller diameter or more is refused: Hertz's law, and the
packing, no longer hold (the bodies pass through one another).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.hertz import contact_time, max_overlap
from hexdem.model.materials import Material, hertz_coefficient, hertz_stiffness, sphere_mass
from hexdem.model.precompression import spring_stiffness


def fastest_approach_m_s(model) -> float:
    """The largest relative speed [m/s] of two bodies of the :class:`~hexdem.model.granular.GranularModel`
    ``model`` at t = 0, or of one against its walls, at rest: the greatest distance between two of
    the initial velocities (and zero, with walls), found among the vertices of their convex hull."""
    from scipy.spatial import ConvexHull  # scipy: only where a state is read

    velocities = model.initial_velocities_m_s()
    points = np.unique(np.vstack([velocities, np.zeros((1, 2))] if model.walls else [velocities]), axis=0)
    if len(points) > 3:
        points = points[ConvexHull(points, qhull_options="QJ").vertices]
    return float(np.linalg.norm(points[:, None] - points[None], axis=-1).max())


def _contact_time_s(reduced_mass: float, coefficient: float, speed_m_s: float, names: str, diameter_m: float) -> float:
    """The Hertz contact time [s] of a pair (``names``) meeting head on at ``speed_m_s``; refused if
    they would overlap by half of ``diameter_m`` (the smaller one's) or more."""
    overlap = float(max_overlap(reduced_mass, coefficient, speed_m_s))
    if overlap >= diameter_m / 2:
        raise HexdemError(f"at {speed_m_s:.3g} m/s, {names} meeting head on would overlap by {overlap / diameter_m:.3g} "
                          "diameters (from half a diameter on, Hertz's law no longer holds and they pass through one "
                          "another): lower the fastest speed of the impacts and the initial state")
    return float(contact_time(reduced_mass, coefficient, speed_m_s))


def pair_contact_time_s(a: Material, da: float, b: Material, db: float, speed_m_s: float) -> float:
    """Hertz contact time [s] of spheres of materials ``a``, ``b`` and diameters ``da``, ``db`` [m]
    meeting head-on at ``speed_m_s``."""
    ma, mb = float(sphere_mass(da, a)), float(sphere_mass(db, b))
    coefficient = hertz_stiffness(a, b) * math.sqrt(da * db / (2 * (da + db)))
    return _contact_time_s(ma * mb / (ma + mb), coefficient, speed_m_s, f"{a.name} and {b.name}", min(da, db))


def sized_bodies(model) -> tuple[tuple[Material, float], ...]:
    """(material, smallest diameter [m]) of each bead material of the :class:`~hexdem.model.granular.GranularModel`
    ``model``: the smallest beads of a material touch the shortest (t_c ∝ d at a given speed)."""
    diameters, ids = model.lattice.diameters_m, model.material_ids[:len(model.lattice)]
    return tuple((model.materials[k], float(diameters[ids == k].min())) for k in np.unique(ids))


def impact_contact_time_s(bead: Material, diameter_m: float, region_materials, impacts,
                          precompression_n: float = 0.0, sized=()) -> float:
    """The shortest contact time [s] of the pairs the impacts set moving.

    ``region_materials``: the other bead materials of the packing; ``impacts``: per impact (and
    per fastest approach of an initial state), (speed [m/s], its striker (material, diameter [m])
    when of its own material or size, else None). At each impact's speed: two beads (the paper's pair, computed as always), every
    other pair of bead materials, and the striker with each bead material; ``sized`` adds bodies
    (material, diameter [m]) of other sizes (:func:`sized_bodies`). With
    ``precompression_n`` > 0 [N], also half the period of two beads on the linearized
    contact, π sqrt(m/2k)."""
    mass = float(sphere_mass(diameter_m, bead))
    coefficient = float(hertz_coefficient(diameter_m, bead))
    bodies = [(bead, diameter_m)] + [(m, diameter_m) for m in dict.fromkeys(region_materials) if m != bead]
    bodies += [body for body in dict.fromkeys(sized) if body not in bodies]
    times = []
    for speed, striker in impacts:
        pairs = list(itertools.combinations_with_replacement(bodies, 2))[1:]
        pairs += [(striker, body) for body in bodies] if striker is not None else []
        times += [_contact_time_s(mass / 2, coefficient, speed, f"two {bead.name} beads", diameter_m),
                  *(pair_contact_time_s(a, da, b, db, speed) for (a, da), (b, db) in pairs)]
    hertz = min(times)
    if precompression_n <= 0:
        return hertz
    return min(hertz, math.pi * math.sqrt(mass / 2 / spring_stiffness(precompression_n, coefficient)))
