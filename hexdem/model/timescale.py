r"""The natural time scale of an impact: the shortest Hertz contact time among the pairs it sets
moving, from which the time step and the sampling follow (see
:func:`~hexdem.model.run_settings.contact_time_s`).

Two spheres meeting at relative speed V touch for :math:`t_c = 2.9432\, (μ^2/(A^2 V))^{1/5}`
(:func:`~hexdem.model.hertz.contact_time`, μ the reduced mass, :math:`A = k_n \sqrt{R_\text{eff}}`). With one
material the pair is two equal beads; unlike beads and strikers of their own material or size
add their pairs, and a precompressed packing its linearized contact's half period.

The contact is shortest at the fastest approach, as :math:`V^{−1/5}`. An impact sets one body moving
at V0 against bodies at rest; an initial state may set any bodies moving, and the fastest
approach it can make is the largest relative speed :math:`\left|v_i − v_j\right|` of two of its bodies, or of one
against the walls at rest (:func:`fastest_approach_m_s`): a bead given 100 V0 needs a
step :math:`100^{1/5} = 2.5` times shorter. A speed at which two bodies meeting head on would press
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
from hexdem.model.solitary_wave import chain_speed_scale_m_s, solitary_speed_m_s


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
        raise HexdemError(
            f"at {speed_m_s:.3g} m/s, {names} meeting head on would overlap by {overlap / diameter_m:.3g} "
            "diameters (from half a diameter on, Hertz's law no longer holds and they pass through one "
            "another): lower the fastest speed of the impacts and the initial state"
        )
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
    diameters, ids = model.packing.diameters_m, model.material_ids[: len(model.packing)]
    return tuple((model.materials[k], float(diameters[ids == k].min())) for k in np.unique(ids))


def impact_contact_time_s(
    bead: Material, diameter_m: float, region_materials, impacts, precompression_n: float = 0.0, sized=()
) -> float:
    """The shortest contact time [s] of the pairs the impacts set moving.

    ``region_materials``: the other bead materials of the packing; ``impacts``: per impact (and
    per fastest approach of an initial state), (speed [m/s], its striker (material, diameter [m])
    when of its own material or size, else None). At each impact's speed: two beads (the paper's pair, computed as
    always), every
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
        times += [
            _contact_time_s(mass / 2, coefficient, speed, f"two {bead.name} beads", diameter_m),
            *(pair_contact_time_s(a, da, b, db, speed) for (a, da), (b, db) in pairs),
        ]
    hertz = min(times)
    if precompression_n <= 0:
        return hertz
    return min(hertz, math.pi * math.sqrt(mass / 2 / spring_stiffness(precompression_n, coefficient)))


#: Round-off, in layers, below which a bead counts as on a layer's line rather than past it.
LAYER_ROUND_OFF = 1e-9


def own_contact_times_s(model) -> dict[int, float]:
    """{material id: the Hertz contact time [s] of two beads of that material and the nominal
    diameter meeting at the first impact's speed}, for the packing's bead materials."""
    packing, speed, d = model.packing, model.impacts[0].speed_m_s, model.packing.diameter_m
    return {
        int(k): float(
            contact_time(
                float(sphere_mass(d, model.materials[k])) / 2, float(hertz_coefficient(d, model.materials[k])), speed
            )
        )
        for k in np.unique(model.material_ids[: len(packing)])
    }


def crossing_time_s(model, linear_contact_s: float | None = None) -> float:
    r"""The time [s] the default duration gives the leading pulse to cross the packing: one layer
    (√3/2 d, the triangular lattice's row spacing) at a time, from each struck bead along its
    impact to the packing's far side, each layer taking the two-bead Hertz contact time of the
    quickest material it holds (:func:`own_contact_times_s`): the front runs through the quickest
    material a layer offers, and through a softer one where a whole layer is of it (brass behind a
    steel|brass interface:
    :math:`((ρ_\text{brass} E^*_\text{steel}) / (ρ_\text{steel} E^*_\text{brass}))^{2/5} = 1.26` times longer
    per layer, as :math:`t_c ∝ (m/A)^{2/5}` at a given speed). A
    precompressed packing's ``linear_contact_s`` (its linearized contact's half period) replaces
    the Hertz time, scaled alike. For a packing of one material this is the layer count times
    the two-bead contact time. The largest over the impacts."""
    packing = model.packing
    own = own_contact_times_s(model)
    fastest = min(own.values())
    pace = np.vectorize(own.get, otypes=[float])(model.material_ids[: len(packing)])  # each bead's material's
    scale = 1.0 if linear_contact_s is None else linear_contact_s / fastest
    layer_m = math.sqrt(3) / 2 * packing.diameter_m
    times = []
    for bead, impact in zip(model.struck_beads, model.impacts):
        depth = (packing.positions_m - packing.positions_m[bead]) @ impact.direction
        count = math.ceil(float(depth.max()) / layer_m)
        layers = np.ceil(depth / layer_m - LAYER_ROUND_OFF).astype(int)  # a bead on a layer's line is in it
        ahead = (layers > 0) & (layers <= count)
        quickest = np.full(count + 1, np.inf)
        np.minimum.at(quickest, layers[ahead], pace[ahead])
        quickest[np.isinf(quickest)] = fastest  # a layer no bead's centre falls in
        paces, counts = np.unique(quickest[1:], return_counts=True)  # count × pace: exact for one material
        times.append(scale * sum(float(n * p) for p, n in zip(paces, counts)))
    return max(times)


def wall_contact_time_s(model) -> float:
    """The longest head-on Hertz contact [s] of a struck bead with the walls at its impact's speed
    (mass m against a rigid body, A = k_n sqrt(r)); 0 without walls."""
    walls = [0.0]
    if model.walls:
        masses, radii = model.masses_kg, model.packing.radii_m
        for bead, impact in zip(model.struck_beads, model.impacts):
            coefficient = float(model.wall_stiffness_pa([bead])[0]) * math.sqrt(radii[bead])
            walls.append(float(contact_time(masses[bead], coefficient, impact.speed_m_s)))
    return max(walls)


def solitary_crossing_time_s(model, contact_s: float, wall_contact_s: float) -> float:
    r"""The default duration [s] of a walled crystal whose pulse runs along straight rows of touching
    beads (a square crystal's row, a centered square's rows): long enough for the leading pulse to
    reach the far end and peak there, short enough to end before the far wall's reflection reaches
    the beads before it.

    The pulse is Nesterenko's solitary wave, which does not decay along a chain: it crosses the
    packing's depth D along each impact (from the struck bead to the farthest bead ahead) at no
    more than :math:`V_s = (16/25)^{1/5} c^{4/5} V_0^{1/5}` (:func:`~hexdem.model.solitary_wave.solitary_speed_m_s`,
    c of the quickest material: its beads never exceed V0). The far bead then peaks within half
    its head-on contact with the wall (``wall_contact_s``, the turning point of its push) or,
    without walls, within one contact time ``contact_s`` as it leaves its neighbour; one more
    contact time lets the tracker see the peak pass. The wall's reflection needs the other half of
    that wall contact, and a layer's transit, to come back: the 15 × 15 steel square's last bead
    peaks 0.53 ms after the strike, its neighbour meets the reflection at 0.74 ms, and this gives
    0.68 ms."""
    packing = model.packing
    fastest = max(chain_speed_scale_m_s(model.materials[k]) for k in np.unique(model.material_ids[: len(packing)]))
    times = []
    for bead, impact in zip(model.struck_beads, model.impacts):
        depth_m = float(np.max((packing.positions_m - packing.positions_m[bead]) @ impact.direction))
        times.append(depth_m / solitary_speed_m_s(fastest, impact.speed_m_s))
    far_end_s = wall_contact_s / 2 if model.walls else contact_s
    return max(times) + max(far_end_s, contact_s) + contact_s


def striker_launch_s(model) -> float:
    """How much longer [s] the slowest striker touches its bead than two beads of that bead's
    material touch (0 for strikers no slower: the pulse a soft striker launches needs that much
    more time to enter the packing)."""
    own, struck, ids = own_contact_times_s(model), model.struck_beads, model.material_ids
    extra = [
        pair_contact_time_s(
            model.materials[ids[struck[k]]],
            float(model.packing.diameters_m[struck[k]]),
            impact.striker_material or model.bead,
            impact.striker_diameter_m or model.packing.diameter_m,
            impact.speed_m_s,
        )
        - own[int(ids[struck[k]])]
        for k, impact in enumerate(model.impacts)
        if impact.striker
    ]
    return max([0.0, *extra])
