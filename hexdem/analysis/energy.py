r"""Total mechanical energy of a granular state: kinetic (translational, and rotational for a
frictional model's turning spheres, ½ I ω² with I = (2/5) m r²) + Hertz contact (+ gravity) energy.
Mindlin's tangential springs and what friction dissipates are not counted: a frictional model's
audit is that of a dissipative one (:attr:`~hexdem.model.granular.GranularModel.dissipative`).

LAMMPS reports no potential energy for granular pairs, so hexdem computes it itself from
positions: a contact of overlap δ stores :math:`U = \tfrac{2}{5} k_n \sqrt{R_\text{eff}}\, δ^{5/2}` (the
integral of :math:`F = k_n \sqrt{R_\text{eff}}\, δ^{3/2}`; with equal spheres this is the paper's
:math:`V = \tfrac{2}{5} A δ^{5/2}`, eq. (2)).
Every pair closer than the sum of radii counts, as in LAMMPS, not only lattice bonds.
Under constant forces F (gravity m g in the tilted set-up of Sec. VI-A; the force holding a
precompressed packing's struck bead) the conserved total also holds their potential −Σ F·u
of the displacements u from t = 0.
"""

from __future__ import annotations

import numpy as np

from hexdem.analysis.compiled import audit_part, bind_audit, pairs_within
from hexdem.model.granular import GranularModel
from hexdem.model.walls import CurvedWall

#: Candidate pairs are found within contact distance + this many bead diameters, and found
#: again once a body has moved half of it (a Verlet list).
PAIR_SKIN_D = 0.1


def _pairs(positions_m, cutoff_m: float) -> tuple[np.ndarray, np.ndarray]:
    from scipy.spatial import cKDTree  # (a slow import: not on a rank's way to its first sample)

    i, j = cKDTree(positions_m).query_pairs(cutoff_m, output_type="ndarray").T
    return i, j


def _hertz_energies_j(stiffness_pa, r_eff_m, overlap_m) -> np.ndarray:
    r""":math:`\tfrac{2}{5} k_n \sqrt{R_\text{eff}}\, δ^{5/2}` [J] of each contact with overlap δ > 0."""
    return 0.4 * np.asarray(stiffness_pa, float) * np.sqrt(r_eff_m) * overlap_m**2.5


def hertz_energy_j(stiffness_pa, r_eff_m, overlap_m) -> float:
    r""":math:`\sum \tfrac{2}{5} k_n \sqrt{R_\text{eff}}\, δ^{5/2}` [J] over contacts with overlap δ > 0 (k_n per
    contact; one
    value factored out when all are equal, the single-material sum as it always was)."""
    stiffness_pa = np.asarray(stiffness_pa, float)
    terms = np.sqrt(r_eff_m) * overlap_m**2.5
    if stiffness_pa.size and np.all(stiffness_pa == stiffness_pa.flat[0]):
        return 0.4 * float(stiffness_pa.flat[0]) * float(np.sum(terms))
    return 0.4 * float(np.sum(stiffness_pa * terms))


def _pair_constants(model: GranularModel, i, j, radii) -> tuple:
    """(i, j, k_n, R_eff) of the candidate pairs ``i``, ``j``: what a contact of each would be."""
    return i, j, model.contact_stiffness_pa(i, j), radii[i] * radii[j] / (radii[i] + radii[j])


def _pair_contacts(positions_m, radii, candidates):
    """(i, j, k_n, R_eff, δ) of the touching pairs among the ``candidates`` (:func:`_pair_constants`)."""
    i, j, stiffness, r_eff = candidates
    overlap = radii[i] + radii[j] - np.linalg.norm(positions_m[i] - positions_m[j], axis=1)
    touching = overlap > 0
    return i[touching], j[touching], stiffness[touching], r_eff[touching], overlap[touching]


def _wall_constants(model: GranularModel, bodies=None) -> list[tuple]:
    """Per wall, (wall, its members' rows, their k_n against it, their radii, their contact radii
    R_eff: R against a plane). ``bodies``: the body index of each row of the positions the
    contacts are sought in (None: every body, row = body)."""
    radii = model.diameters_m / 2
    constants = []
    for wall in model.walls:
        rows = wall.members if bodies is None else np.flatnonzero(np.isin(bodies, wall.members))
        members = rows if bodies is None else bodies[rows]
        constants.append(
            (wall, rows, model.wall_stiffness_pa(members), radii[members], wall.contact_radii_m(radii[members]))
        )
    return constants


def _wall_contacts(positions_m, walls) -> list[tuple]:
    """Per wall of ``walls`` (:func:`_wall_constants`), (beads, k_n, R_eff, δ) of its members
    that touch it."""
    contacts = []
    for wall, members, stiffness, radii, contact_radii in walls:
        depth = -wall.gaps_m(positions_m[members], radii)
        inside = depth > 0
        contacts.append((members[inside], stiffness[inside], contact_radii[inside], depth[inside]))
    return contacts


def _wall_geometry(wall) -> tuple[int, tuple[float, float], float]:
    """(curved, point, length [m]) of a wall: (0, its normal, its offset) for a flat
    :class:`~hexdem.model.walls.Wall`, (1, its centre, its radius) for a
    :class:`~hexdem.model.walls.CurvedWall`."""
    if isinstance(wall, CurvedWall):
        return 1, wall.centre_m, wall.radius_m
    return 0, wall.normal, wall.offset_m


def _wall_rows(walls, regions) -> dict[str, np.ndarray]:
    r"""The walls of :func:`_wall_constants` as :func:`~hexdem.analysis.compiled.audit_part` reads
    them, by name: per wall where its members start and end in the member arrays (``bounds``) and its
    :func:`_wall_geometry` (``curved``, ``points``, ``lengths``); per member its row, radius,
    :math:`\tfrac{2}{5} k_n \sqrt{R_\text{eff}}` (``wall_coefficient``) and its row's region
    (``wall_regions``; ``regions``, by row)."""
    bounds = np.cumsum([0, *(len(wall[1]) for wall in walls)])
    curved, points, lengths = zip(*(_wall_geometry(wall[0]) for wall in walls)) if walls else ((), (), ())

    def joined(k: int, dtype=float) -> np.ndarray:
        return np.concatenate([np.zeros(0, dtype), *(np.asarray(wall[k], dtype) for wall in walls)])

    rows = joined(1, np.int64)
    return {
        "bounds": bounds.astype(np.int64),
        "curved": np.array(curved, np.int64),
        "points": np.array(points, float).reshape(-1, 2),
        "lengths": np.array(lengths, float),
        "rows": rows,
        "radii": joined(3),
        "wall_coefficient": 0.4 * joined(2) * np.sqrt(joined(4)),
        "wall_regions": regions[rows].astype(np.int64),
    }


def _wall_energy_j(walls) -> float:
    """Hertz energy [J] of the wall contacts (:func:`_wall_contacts`), wall by wall."""
    return sum((hertz_energy_j(*wall[1:]) for wall in walls), 0.0)


def contact_energy_j(positions_m, model: GranularModel) -> float:
    """Hertz energy [J] of all bead–bead and bead–wall overlaps at ``positions_m`` (n_bodies, 2)."""
    positions_m = np.asarray(positions_m, float)
    radii = model.diameters_m / 2
    pairs = _pair_contacts(positions_m, radii, _pair_constants(model, *_pairs(positions_m, 2 * radii.max()), radii))
    return hertz_energy_j(*pairs[2:]) + _wall_energy_j(_wall_contacts(positions_m, _wall_constants(model)))


def kinetic_energy_j(velocities_m_s, model: GranularModel) -> float:
    """Translational kinetic energy Σ ½ M v² [J]."""
    return float(0.5 * np.sum(model.masses_kg * np.sum(np.asarray(velocities_m_s) ** 2, axis=1)))


def inertia_kg_m2(model: GranularModel) -> np.ndarray:
    """(n_bodies,) moments of inertia of solid spheres, (2/5) m r² [kg m²]."""
    return 0.4 * model.masses_kg * (model.diameters_m / 2) ** 2


class EnergyAudit:
    """Total energy [J] of successive states of one run, for the drift of a conservative model.

    Equal to :func:`kinetic_energy_j` plus :func:`contact_energy_j` minus the work of the constant
    forces (``gravity_m_s2``, if given, and the model's held force on a precompressed packing's
    struck bead), but what does not change during a run (masses, radii, regions, each wall's
    members and stiffness, the candidate pairs' stiffness) is worked out once, and the candidate
    contact pairs are kept between calls and searched again only after some body has moved half
    of :data:`PAIR_SKIN_D` bead diameters (or the bodies seen changed), so a large packing costs a
    few vector operations per state instead of a tree search.

    **A share of the bodies.** :meth:`part` audits the bodies one MPI rank owns, given also the
    positions of its ghosts (the other ranks' bodies near its own, as LAMMPS keeps them): each
    body's kinetic energy and external work, half of each of its contacts' Hertz energy (the
    other half belongs to the other body's owner) and its wall contacts. The parts of all ranks
    sum to the whole state's audit, to round-off.
    """

    def __init__(self, model: GranularModel, gravity_m_s2=None, compiled: bool = False):
        self.model = model
        self.start_m = model.initial_positions_m()
        self.masses_kg = model.masses_kg
        self.inertia_kg_m2 = inertia_kg_m2(model)
        self.radii_m = model.diameters_m / 2
        self.skin_m = PAIR_SKIN_D * model.packing.diameter_m
        self.region_names, self.regions = energy_regions(model)
        gravity = np.zeros(2) if gravity_m_s2 is None else np.asarray(gravity_m_s2, float)
        self.external_n = model.external_forces_n() + self.masses_kg[:, None] * gravity
        self.everybody = np.arange(model.n_bodies)
        self.compiled = compiled
        self._listed, self._listed_at, self._candidates, self._walls, self._rows = None, None, None, None, None
        self._no_spins = np.zeros(0)

    def _listed_for(self, bodies, n_own: int) -> bool:
        """Whether the contacts at hand were listed for ``bodies`` with the first ``n_own`` audited
        (the very array, kept by :meth:`_list`, or an equal one, which is kept in its place: the
        next call with it spares the comparison)."""
        if self._listed is None or n_own != self._listed[1]:
            return False
        if bodies is not self._listed[0]:
            if not np.array_equal(bodies, self._listed[0]):
                return False
            self._listed = (bodies, n_own)
        return True

    def _list(self, bodies, n_own: int, positions_m) -> None:
        """List the candidates among the rows of ``positions_m`` (bodies ``bodies``, the first ``n_own``
        audited) with an audited body: the candidates (i, j, k_n, R_eff) of rows within contact
        distance and the skin (:func:`_pair_constants`; found compiled, :func:`~hexdem.analysis.compiled.pairs_within`,
        or by scipy's tree on the NumPy way), kept from one search to the next until a body
        has moved half the skin, and the walls' audited members (:func:`_wall_constants`)."""
        self._listed, self._listed_at = (bodies, n_own), positions_m.copy()
        i, j = (pairs_within if self.compiled else _pairs)(positions_m, 2 * self.radii_m.max() + self.skin_m)
        keep = (i < n_own) | (j < n_own)
        i, j = i[keep], j[keep]
        self._candidates = (i, j, *_pair_constants(self.model, bodies[i], bodies[j], self.radii_m)[2:])
        self._walls = _wall_constants(self.model, bodies[:n_own])
        if self.compiled:
            self._rows = self._row_constants(bodies, n_own)

    def _row_constants(self, bodies, n_own: int):
        r"""What :func:`~hexdem.analysis.compiled.audit_part` reads of the listed rows, laid out and
        bound once per list (:func:`~hexdem.analysis.compiled.bind_audit`): where they were listed and
        half the skin; per candidate pair its rows, sum of radii, :math:`\tfrac{2}{5} k_n \sqrt{R_\text{eff}}`
        and the regions of its two rows (−1 for a ghost); per audited row its body's mass, inertia,
        region, start position and constant force; the walls' audited members (:func:`_wall_rows`)."""
        i, j, stiffness, r_eff = self._candidates
        regions = self.regions[bodies]
        own = np.where(np.arange(len(bodies)) < n_own, regions, -1)
        audited = bodies[:n_own]
        return bind_audit(
            listed_at=self._listed_at,
            distance=self.skin_m / 2,
            i=i,
            j=j,
            contact_m=self.radii_m[bodies[i]] + self.radii_m[bodies[j]],
            coefficient=0.4 * stiffness * np.sqrt(r_eff),
            region_i=own[i],
            region_j=own[j],
            masses=self.masses_kg[audited],
            inertia=self.inertia_kg_m2[audited],
            regions=regions[:n_own],
            start=self.start_m[audited],
            external=self.external_n[audited],
            **_wall_rows(self._walls, regions),
            n_regions=len(self.region_names),
        )

    def part(self, bodies, n_own: int, positions_m, velocities_m_s, angular_velocities_s=None) -> np.ndarray:
        """The audit's sums over the bodies ``bodies[:n_own]`` (indices; the rest are ghosts, see the
        class docstring) at ``positions_m`` (len(bodies), 2), ``velocities_m_s`` and spins ω_z
        (n_own,) [rad/s] (None: spheres that do not turn): [total energy, translational kinetic,
        rotational kinetic, then the (R, 2) kinetic and contact energy of each
        :func:`energy_regions` region, flattened] [J], to be summed over the ranks.

        ``bodies`` is kept, not copied, with the contacts listed for it: a caller that passes the
        same array again for the same bodies (and never changes it) spares the audit comparing them."""
        bodies, positions_m = np.asarray(bodies), np.asarray(positions_m, float)
        velocities_m_s = np.asarray(velocities_m_s, float)
        if self.compiled:
            return self._compiled_part(bodies, n_own, positions_m, velocities_m_s, angular_velocities_s)
        if not self._listed_for(bodies, n_own) or self._moved_beyond(positions_m, self.skin_m / 2):
            self._list(bodies, n_own, positions_m)
        contact = _pair_energies_j(
            _pair_contacts(positions_m, self.radii_m[bodies], self._candidates),
            self.regions[bodies],
            len(self.region_names),
            n_own,
        )
        _add_wall_energies_j(
            contact, _wall_contacts(positions_m, self._walls), self.regions[bodies], len(self.region_names)
        )
        translational, rotational, kinetic, external = self._body_energies_j(
            bodies[:n_own], positions_m[:n_own], velocities_m_s, angular_velocities_s
        )
        by_region = np.column_stack([kinetic, contact])
        return np.concatenate([[float(np.sum(by_region)) - external, translational, rotational], by_region.ravel()])

    def _compiled_part(self, bodies, n_own: int, positions_m, velocities_m_s, angular_velocities_s) -> np.ndarray:
        """:meth:`part` in one compiled pass (:func:`~hexdem.analysis.compiled.audit_part`), which first
        checks that no body has moved half the skin since the contacts were listed (else they are
        listed again and the pass repeated)."""
        spins = self._no_spins if angular_velocities_s is None else np.asarray(angular_velocities_s, float)

        def measure() -> np.ndarray:
            return audit_part(self._rows, positions_m, velocities_m_s, spins, len(self.region_names))

        if not self._listed_for(bodies, n_own):
            self._list(bodies, n_own, positions_m)
        sums = measure()
        if not len(sums):
            self._list(bodies, n_own, positions_m)
            sums = measure()
        return sums

    def _moved_beyond(self, positions_m, distance_m: float) -> bool:
        """Whether a body has moved more than ``distance_m`` since the candidates were listed."""
        return np.max(np.linalg.norm(positions_m - self._listed_at, axis=1)) > distance_m

    def _body_energies_j(self, own, positions_m, velocities_m_s, angular_velocities_s) -> tuple:
        """(translational and rotational kinetic energy [J], (R,) kinetic energy [J] of each region, the
        work [J] of the constant forces) of the audited bodies ``own`` at ``positions_m`` with
        ``velocities_m_s`` and spins (None: spheres that do not turn)."""
        translational = 0.5 * self.masses_kg[own] * np.sum(velocities_m_s**2, axis=1)
        rotational = (
            np.zeros(len(own))
            if angular_velocities_s is None
            else 0.5 * self.inertia_kg_m2[own] * np.asarray(angular_velocities_s, float) ** 2
        )
        kinetic = _by_region(self.regions[own], translational + rotational, len(self.region_names))
        external = float(np.sum((positions_m - self.start_m[own]) * self.external_n[own]))
        return float(np.sum(translational)), float(np.sum(rotational)), kinetic, external

    def __call__(self, positions_m, velocities_m_s, angular_velocities_s=None) -> float:
        return self.measure(positions_m, velocities_m_s, angular_velocities_s)[0]

    def measure(self, positions_m, velocities_m_s, angular_velocities_s=None) -> tuple[float, np.ndarray]:
        """(the total energy [J] of the whole state, (R, 2) kinetic (translational and rotational)
        and contact energy [J] of each :func:`energy_regions` region), from one search of the
        contacts."""
        sums = self.part(self.everybody, len(self.everybody), positions_m, velocities_m_s, angular_velocities_s)
        return float(sums[0]), sums[3:].reshape(len(self.region_names), 2)


def energy_regions(model: GranularModel) -> tuple[list[str], np.ndarray]:
    """(names, (n_bodies,) region of each body): the beads by material, then the strikers, if
    any, as one region of their own (so that what they keep is not counted in the packing)."""
    names = [m.name for m in model.materials[: 1 + len(model.extra_materials)]]
    regions = model.packing.material_ids
    if model.has_striker:
        names, regions = [*names, "striker"], np.append(regions, np.full(len(model.strikers), len(names)))
    return names, regions


def _by_region(regions, energies_j, n_regions: int) -> np.ndarray:
    """(R,) sums of ``energies_j`` by each body's region (float even when empty, unlike bincount's)."""
    return np.bincount(regions, energies_j, n_regions).astype(float)


def _pair_energies_j(pairs, regions, n_regions: int, n_own: int) -> np.ndarray:
    """(R,) Hertz energy [J] of the touching ``pairs`` (i, j, k_n, R_eff, δ of rows, whose regions are
    ``regions``): a contact's half to each of its bodies' regions, for the first ``n_own`` rows only."""
    i, j, *pair = pairs
    halves = _hertz_energies_j(*pair) / 2
    contact = np.zeros(n_regions)
    for side in (i, j):
        own = side < n_own
        contact += _by_region(regions[side[own]], halves[own], n_regions)
    return contact


def _add_wall_energies_j(contact_j, walls, regions, n_regions: int) -> None:
    """Add to ``contact_j`` (R,) the Hertz energy [J] of the wall contacts (:func:`_wall_contacts`),
    each to its bead's region, wall by wall."""
    for beads, *wall in walls:
        contact_j += _by_region(regions[beads], _hertz_energies_j(*wall), n_regions)


#: The audit's yardstick never falls below this fraction of the total energy: the round-off of a
#: large static energy is not integration error. A precompressed packing's overlaps (~1e-6 m)
#: are differences of centre distances (~1e-2 m), so its static energy carries relative
#: round-off near 1e-11 (measured: 1.2e-12 of E(0) with 5 N per contact and no impact).
ROUND_OFF = 1e-8


def energy_scale_j(energies_j, impact_energy_j: float) -> float:
    """The audit's yardstick [J]: the energy the impact brought in, K(0) (a precompressed or
    settled packing also stores static contact energy, which would dilute the figures), but at
    least :data:`ROUND_OFF` of E(0)."""
    return max(impact_energy_j, ROUND_OFF * abs(float(np.asarray(energies_j)[0])))


def energy_error(energies_j, impact_energy_j: float, dissipative: bool = False) -> float:
    r"""The energy audit's figure of merit, 0 for an exact integrator, relative to
    :func:`energy_scale_j`.

    Conservative model: max_t |E(t) − E(0)|. Dissipative model (restitution < 1): the energy may
    only fall, so the largest rise above the lowest energy reached before,
    :math:`\max_t [E(t) − \min_{s ≤ t} E(s)]`.
    """
    energies_j = np.asarray(energies_j, float)
    scale = energy_scale_j(energies_j, impact_energy_j)
    if dissipative:
        return float(np.max(energies_j - np.minimum.accumulate(energies_j)) / scale)
    return float(np.max(np.abs(energies_j - energies_j[0])) / scale)


def rotational_share(rotational_j, region_energies_j) -> float:
    """The largest share of the kinetic and contact energy (the regions' sum) held in rotation,
    over the audited times (0 where there is no energy)."""
    totals = np.array([np.sum(energies) for energies in region_energies_j])
    shares = np.divide(rotational_j, totals, out=np.zeros(len(totals)), where=totals > 0)
    return float(shares.max(initial=0.0))
