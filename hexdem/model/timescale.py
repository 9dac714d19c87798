"""The natural time scale of an impact: the shortest Hertz contact time among the pairs it sets
moving, from which the time step and the sampling follow (see
:meth:`~hexdem.model.config.RunConfig.contact_time_s`).

Two spheres meeting at relative speed V touch for t_c = 2.9432 (μ²/(A² V))^{1/5}
(:func:`~hexdem.model.hertz.contact_time`, μ the reduced mass, A = k_n sqrt(R_eff)). With one
material the pair is two equal beads; unlike beads and strikers of their own material or size
add their pairs, and a precompressed packing its linearized contact's half period.
"""

from __future__ import annotations

import itertools
import math

from hexdem.model.hertz import contact_time
from hexdem.model.materials import Material, hertz_coefficient, hertz_stiffness, sphere_mass
from hexdem.model.precompression import spring_stiffness


def pair_contact_time_s(a: Material, da: float, b: Material, db: float, speed_m_s: float) -> float:
    """Hertz contact time [s] of spheres of materials ``a``, ``b`` and diameters ``da``, ``db`` [m]
    meeting head-on at ``speed_m_s``."""
    ma, mb = float(sphere_mass(da, a)), float(sphere_mass(db, b))
    coefficient = hertz_stiffness(a, b) * math.sqrt(da * db / (2 * (da + db)))
    return float(contact_time(ma * mb / (ma + mb), coefficient, speed_m_s))


def impact_contact_time_s(bead: Material, diameter_m: float, region_materials, impacts,
                          precompression_n: float = 0.0) -> float:
    """The shortest contact time [s] of the pairs the impacts set moving.

    ``region_materials``: the other bead materials of the packing; ``impacts``: per impact,
    (speed [m/s], its striker (material, diameter [m]) when of its own material or size, else
    None). At each impact's speed: two beads (the paper's pair, computed as always), every
    other pair of bead materials, and the striker with each bead material. With
    ``precompression_n`` > 0 [N], also half the period of two beads on the linearized
    contact, π sqrt(m/2k)."""
    mass = float(sphere_mass(diameter_m, bead))
    coefficient = float(hertz_coefficient(diameter_m, bead))
    bodies = [(bead, diameter_m)] + [(m, diameter_m) for m in dict.fromkeys(region_materials) if m != bead]
    times = []
    for speed, striker in impacts:
        pairs = list(itertools.combinations_with_replacement(bodies, 2))[1:]
        pairs += [(striker, body) for body in bodies] if striker is not None else []
        times += [float(contact_time(mass / 2, coefficient, speed)),
                  *(pair_contact_time_s(a, da, b, db, speed) for (a, da), (b, db) in pairs)]
    hertz = min(times)
    if precompression_n <= 0:
        return hertz
    return min(hertz, math.pi * math.sqrt(mass / 2 / spring_stiffness(precompression_n, coefficient)))
