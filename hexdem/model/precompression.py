r"""A statically precompressed packing (the paper's open question, Sec. VII).

Every bead–bead contact of the packing is to carry the static force f0 [N]. The packing is
built in three steps:

1. **Uniform compression.** Each contact overlaps by :math:`δ_0 = (f_0/A)^{2/3}`
   (:math:`F = A δ^{3/2}`), so
   the lattice shrinks about the struck bead by (d − δ0)/d.
2. **Walls.** Each wall member must receive from its walls the force its missing neighbours'
   contacts would have exerted, f0 Σ (−u) over the unit vectors u towards them. A bead on a
   straight edge misses two neighbours at ±30° from the wall's normal: √3 f0, met when the wall
   overlaps it by :math:`δ_w = (\sqrt{3} f_0 / A_w)^{2/3}`
   (:math:`A_w = k_{n,\text{wall}} \sqrt{R}`). A bead at a 120° corner
   misses three (2 f0 along the corner's bisector) and touches two walls whose normals are ±30°
   from it, so each must give 2 f0/√3: flat walls at δw would squeeze it with 3 f0 and, relaxed,
   spread errors of several per cent through a hexagon of 21 per edge. Each wall therefore
   meets each of its members at the member's own overlap: the corner beads see their walls
   retracted by about a micrometre (a separate plane each). A 60° corner (the half-hexagon)
   needs √3 f0 from each wall, as an edge bead does.
3. **The hole.** The struck bead sits in the hole of its wall; it is held by the force its
   missing wall would exert, √3 f0 along that wall's normal, a constant force during the whole
   run (and the impact).

Built this way, the packing is in static equilibrium bead by bead, every contact at f0.

**Linear waves.** About f0 a contact is a spring of stiffness
:math:`k = dF/dδ = \tfrac{3}{2} A δ_0^{1/2} = \tfrac{3}{2} A^{2/3} f_0^{1/3}`. A triangular lattice of beads of mass m
joined to their 6 neighbours
(spacing a) by such springs stores, under a uniform strain ε, the energy density
W = (k a²/2A₀) Σ_bonds (n·ε·n)² over its 3 bond directions per bead (A₀ = (√3/2) a² per bead);
Σ n_i n_j n_k n_l = (3/8)(δ_ij δ_kl + δ_ik δ_jl + δ_il δ_jk) gives Lamé constants λ = μ =
(√3/4) k, so C₁₁ = λ + 2μ = (3√3/4) k and, with the areal density ρ = m/A₀, the
long-wavelength longitudinal sound speed :math:`c_L = \sqrt{C_{11}/ρ} = \sqrt{9/8}\, a \sqrt{k/m}`
(:func:`longitudinal_sound_speed`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.packing import Packing
from hexdem.model.triangular import BOND_STEPS
from hexdem.model.walls import Wall

#: A precompression may squeeze each contact by less than this fraction of a diameter: from half a
#: diameter on, Hertz's law no longer holds (as for an impact, :mod:`hexdem.model.timescale`).
MAX_STATIC_OVERLAP_D = 0.5
#: Neighbour offsets {Δm, Δn} of a bead in the paper's labels: the bond steps and their opposites.
NEIGHBOURS = BOND_STEPS + tuple((-dm, -dn) for dm, dn in BOND_STEPS)


def _unit(step) -> np.ndarray:
    dm, dn = step
    vector = np.array([math.sqrt(3) / 2 * dn, dm / 2])
    return vector / np.linalg.norm(vector)


def static_overlap(force_n: float, coefficient: float) -> float:
    """δ [m] at which a Hertz contact :math:`F = A δ^{3/2}` carries ``force_n``."""
    return (force_n / coefficient) ** (2.0 / 3.0)


def checked_static_overlap(force_n: float, coefficient: float, diameter_m: float) -> float:
    """:func:`static_overlap` of ``force_n`` [N], refused in one line from :data:`MAX_STATIC_OVERLAP_D`
    of ``diameter_m`` [m] on."""
    overlap = static_overlap(force_n, coefficient)
    if not overlap < MAX_STATIC_OVERLAP_D * diameter_m:
        raise HexdemError(
            f"precompression_n = {force_n:g} N would squeeze each contact by {overlap / diameter_m:.3g} "
            f"diameters (from {MAX_STATIC_OVERLAP_D:g} on, Hertz's law no longer holds and the beads "
            "pass through one another): lower it"
        )
    return overlap


def spring_stiffness(force_n: float, coefficient: float) -> float:
    r""":math:`k = dF/dδ = \tfrac{3}{2} A^{2/3} f_0^{1/3}` [N/m] of a Hertz contact precompressed
    by ``force_n``."""
    return 1.5 * coefficient ** (2.0 / 3.0) * force_n ** (1.0 / 3.0)


def longitudinal_sound_speed(force_n: float, coefficient: float, mass_kg: float, spacing_m: float) -> float:
    r""":math:`c_L = \sqrt{9/8}\, a \sqrt{k/m}` [m/s] of a triangular spring lattice (module docstring)."""
    return math.sqrt(9.0 / 8.0) * spacing_m * math.sqrt(spring_stiffness(force_n, coefficient) / mass_kg)


def missing_contact_forces(packing: Packing, force_n: float) -> np.ndarray:
    """(N, 2) force [N] that each bead's missing neighbours would push it with, f0 Σ (−u)."""
    forces = np.zeros((len(packing), 2))
    for b, (m, n) in enumerate(packing.labels.tolist()):
        for step in NEIGHBOURS:
            if packing.index_of(m + step[0], n + step[1]) is None:
                forces[b] -= force_n * _unit(step)
    return forces


def _wall_loads(packing: Packing, needed: np.ndarray) -> dict[tuple[int, int], float]:
    """{(wall index, bead): normal force [N] the wall must give the bead}: one wall takes the
    bead's whole need along its normal, two walls (a corner) share it."""
    touching: dict[int, list[int]] = {}
    for w, wall in enumerate(packing.walls):
        for bead in wall.members.tolist():
            touching.setdefault(bead, []).append(w)
    loads = {}
    for bead, walls in touching.items():
        normals = np.array([packing.walls[w].normal for w in walls]).T
        share = np.linalg.lstsq(normals, needed[bead], rcond=None)[0]
        loads.update({(w, bead): float(f) for w, f in zip(walls, share)})
    return loads


def precompressed_packing(
    packing: Packing, force_n: float, pair_coefficient: float, wall_stiffness_pa: float
) -> Packing:
    r"""The ideal ``packing`` (equal beads) in static equilibrium with every contact at ``force_n``
    [N] (steps 1 and 2): shrunk about the struck bead, each wall split into planes that meet
    their members at the overlap that gives them their missing contacts' force.
    ``pair_coefficient`` A [:math:`\mathrm{N/m^{1.5}}`]; ``wall_stiffness_pa`` k_n,wall
    (:math:`A_w = k_{n,\text{wall}} \sqrt{R}`)."""
    d = packing.diameter_m
    centre = packing.positions_m[packing.struck]
    scale = (d - checked_static_overlap(force_n, pair_coefficient, d)) / d
    shrunk = packing.with_geometry(centre + (packing.positions_m - centre) * scale, packing.diameters_m)
    loads = _wall_loads(shrunk, missing_contact_forces(shrunk, force_n))
    walls = []
    for w, wall in enumerate(shrunk.walls):
        offsets = {}
        for bead in wall.members.tolist():
            coefficient = wall_stiffness_pa * math.sqrt(shrunk.radii_m[bead])
            reach = float(shrunk.positions_m[bead] @ np.asarray(wall.normal) - shrunk.radii_m[bead])
            offset = reach + static_overlap(max(loads[(w, bead)], 0.0), coefficient)
            offsets.setdefault(round(offset, 15), []).append(bead)
        for k, (offset, members) in enumerate(sorted(offsets.items(), key=lambda item: -len(item[1]))):
            name = wall.name if k == 0 else f"{wall.name}_{k}"
            walls.append(Wall(name, wall.normal, offset, np.array(members)))
    return replace(shrunk, walls=tuple(walls))


def hole_force(packing: Packing, force_n: float) -> np.ndarray:
    """(2,) force [N] on the struck bead from its missing wall: its missing contacts' force (√3 f0
    along +x for a bead in the middle of a straight edge)."""
    return missing_contact_forces(packing, force_n)[packing.struck]
