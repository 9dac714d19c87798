"""The physical model shared by every engine: packing + materials + impact, in SI units.

A :class:`GranularModel` says everything an engine needs to integrate the paper's
Hamiltonian (Sec. III): bead masses, Hertz stiffnesses of bead–bead and bead–wall
contacts, the walls, and the initial state. The model is struck by one or more
:class:`Impact` s; each either sets its bead moving or sends a striker sphere at it. The
strikers are extra bodies after the beads, in the order of the impacts, each touching its
bead at t = 0 and moving towards it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.common.checks import is_number
from hexdem.errors import HexdemError
from hexdem.model.contact_law import NO_FRICTION, ContactLaws, Friction
from hexdem.model.dissipation import check_restitution, damping_coefficient
from hexdem.model.initial_state import InitialState
from hexdem.model.materials import DELRIN, STEEL_316, Material
from hexdem.model.packing import Packing, strike_direction, unit_vector
from hexdem.model.units import SI, UnitSystem


@dataclass(frozen=True)
class Impact:
    """One impact on the packing.

    ``speed_m_s`` V0 > 0 [m/s]; ``angle_deg`` direction of motion from +x; ``striker`` False:
    V0 is given to the struck bead (the paper's numerics); True: a striker sphere moving
    at V0 hits it (the experiment), of ``striker_material`` (None: the beads' material) and
    diameter ``striker_diameter_m`` (None: the nominal d). ``bead``: the index of the struck
    bead (None: the packing's struck bead, on the paper's edge, where the angle must point
    into the packing, |angle| < 90°).
    """

    speed_m_s: float
    angle_deg: float = 0.0
    striker: bool = False
    bead: int | None = None
    striker_material: Material | None = None
    striker_diameter_m: float | None = None

    def __post_init__(self):
        if not (is_number(self.speed_m_s) and self.speed_m_s > 0):
            raise HexdemError(f"impact velocity V0 must be > 0 (towards the packing), got {self.speed_m_s}")
        if self.bead is None:
            strike_direction(self.angle_deg)
        elif not (is_number(self.angle_deg) and np.isfinite(self.angle_deg)):
            raise HexdemError(f"impact angle must be a number of degrees, got {self.angle_deg!r}")
        if self.striker_diameter_m is not None and not (
            is_number(self.striker_diameter_m) and self.striker_diameter_m > 0
        ):
            raise HexdemError(f"striker diameter must be > 0 m, got {self.striker_diameter_m!r}")

    @property
    def direction(self) -> np.ndarray:
        """Unit vector of the impact's motion."""
        return unit_vector(self.angle_deg)


#: A striker may start closer than this many d to another body only by round-off (an oblique
#: striker, or the spheres of a flat striker, touch their neighbours exactly).
STRIKER_OVERLAP_D = 1e-6


@dataclass(frozen=True)
class GranularModel:
    """Packing, materials and impacts of one simulation (SI units).

    ``wall`` is the wall-lining material, or None for a packing without walls;
    ``restitution`` and ``wall_restitution`` the coefficients of restitution of bead–bead and
    bead–wall contacts (1: the paper's conservative model; below 1: Tsuji damping, see
    :mod:`hexdem.model.dissipation`); ``held_force_n`` a constant force (fx, fy) [N] on the
    struck bead, the force its missing wall would exert on a precompressed packing
    (:mod:`hexdem.model.precompression`); ``sensor_beads`` bead indices of the sensor particles,
    whose mass is ``sensor_mass_factor`` times a plain bead's (the accelerometer inside).

    Materials: bead material id 0 is ``bead``, ids 1, 2, … are ``extra_materials`` (the
    packing's ``material_ids`` say which bead is which); then the strikers' own materials.
    Every contact is Hertz's with the pair's own E* and R_eff (:meth:`contact_stiffness_pa`);
    ``friction`` adds Mindlin's tangential force and the bodies' rotation (:attr:`laws`).

    Impacts: ``impact`` (the paper's single impact by default) and ``more_impacts``, each on
    its own bead (:attr:`impacts`); ``initial_state`` per-bead velocities and displacements at
    t = 0 besides them (:mod:`hexdem.model.initial_state`; None: at rest where packed).
    """

    packing: Packing
    impact: Impact
    bead: Material = STEEL_316
    wall: Material | None = DELRIN
    restitution: float = 1.0
    wall_restitution: float = 1.0
    held_force_n: tuple[float, float] = (0.0, 0.0)
    sensor_beads: tuple[int, ...] = ()
    sensor_mass_factor: float = 1.0
    extra_materials: tuple[Material, ...] = ()
    more_impacts: tuple[Impact, ...] = ()
    friction: Friction = NO_FRICTION
    initial_state: InitialState | None = None

    def __post_init__(self):
        check_restitution("restitution", self.restitution)
        check_restitution("wall_restitution", self.wall_restitution)
        if not (is_number(self.sensor_mass_factor) and self.sensor_mass_factor > 0):
            raise HexdemError(f"sensor_mass_factor must be > 0, got {self.sensor_mass_factor!r}")
        if len(self.packing) and self.packing.material_ids.max() > len(self.extra_materials):
            raise HexdemError(
                f"bead material id {self.packing.material_ids.max()} has no material "
                f"({1 + len(self.extra_materials)} given)"
            )
        beads = self.struck_beads
        outside = [int(b) for b in beads if not 0 <= b < len(self.packing)]
        if outside:
            raise HexdemError(f"an impact strikes bead index {outside[0]}, not in the packing of {len(self.packing)}")
        struck, counts = np.unique(beads, return_counts=True)
        if counts.max() > 1:
            twice = self.packing.labels[struck[counts.argmax()]]
            raise HexdemError(f"two impacts strike the same bead {{{twice[0]}, {twice[1]}}}")
        if self.has_striker:
            self._check_strikers_clear()

    def _check_strikers_clear(self) -> None:
        """Refuse a striker that starts inside another body (it must come from outside the packing)."""
        positions, radii = self.initial_positions_m(), self.diameters_m / 2
        n_beads = len(self.packing)
        for k, body in enumerate(range(n_beads, self.n_bodies)):
            gaps = np.linalg.norm(positions - positions[body], axis=1) - radii - radii[body]
            gaps[body] = np.inf
            worst = int(np.argmin(gaps))
            if gaps[worst] < -STRIKER_OVERLAP_D * self.packing.diameter_m:
                bead = self.packing.labels[self.struck_beads[self._striker_impacts[k]]]
                other = (
                    f"bead {{{self.packing.labels[worst][0]}, {self.packing.labels[worst][1]}}}"
                    if worst < n_beads
                    else "another striker"
                )
                raise HexdemError(
                    f"the striker of the impact on bead {{{bead[0]}, {bead[1]}}} would start inside "
                    f"{other} ({-gaps[worst] / self.packing.diameter_m:.3g} d overlap): strike from "
                    "outside the packing, or use a velocity impact"
                )

    @property
    def impacts(self) -> tuple[Impact, ...]:
        """Every impact, ``impact`` first."""
        return (self.impact, *self.more_impacts)

    @property
    def struck_beads(self) -> np.ndarray:
        """(n_impacts,) the bead index each impact strikes."""
        return np.array([self.packing.struck if i.bead is None else i.bead for i in self.impacts], dtype=int)

    @property
    def _striker_impacts(self) -> list[int]:
        """Indices into :attr:`impacts` of the impacts by a striker, in body order."""
        return [k for k, impact in enumerate(self.impacts) if impact.striker]

    @property
    def strikers(self) -> tuple[Impact, ...]:
        """The impacts by a striker sphere, in the order of their bodies (after the beads)."""
        return tuple(self.impacts[k] for k in self._striker_impacts)

    @property
    def dissipative(self) -> bool:
        """Whether the contacts dissipate energy: damped (restitution < 1), or frictional."""
        return self.restitution < 1.0 or (bool(self.walls) and self.wall_restitution < 1.0) or self.laws.tangential

    def external_forces_n(self) -> np.ndarray:
        """(n_bodies, 2) constant forces [N] on the bodies: the held force on the struck bead."""
        forces = np.zeros((self.n_bodies, 2))
        forces[self.packing.struck] = self.held_force_n
        return forces

    @property
    def pair_damping(self) -> float:
        """Tsuji's α of bead–bead contacts (0: undamped)."""
        return damping_coefficient(self.restitution)

    @property
    def wall_damping(self) -> float:
        """Tsuji's α of bead–wall contacts (0: undamped)."""
        return damping_coefficient(self.wall_restitution)

    @property
    def has_striker(self) -> bool:
        return any(impact.striker for impact in self.impacts)

    @property
    def n_bodies(self) -> int:
        """Beads plus the strikers (the strikers are the last bodies)."""
        return len(self.packing) + len(self.strikers)

    @property
    def diameters_m(self) -> np.ndarray:
        strikers = [s.striker_diameter_m or self.packing.diameter_m for s in self.strikers]
        return np.concatenate([self.packing.diameters_m, strikers])

    @property
    def _striker_materials(self) -> tuple[Material, ...]:
        return tuple(dict.fromkeys(s.striker_material for s in self.strikers if s.striker_material is not None))

    @property
    def materials(self) -> tuple[Material, ...]:
        """Materials by id: the beads' (``bead``, then ``extra_materials``), then the strikers'
        own, each once."""
        return (self.bead, *self.extra_materials, *self._striker_materials)

    @property
    def material_ids(self) -> np.ndarray:
        """(n_bodies,) each body's index into :attr:`materials`."""
        first = 1 + len(self.extra_materials)
        own = {m: first + k for k, m in enumerate(self._striker_materials)}
        strikers = [own.get(s.striker_material, 0) for s in self.strikers]
        return np.append(self.packing.material_ids, np.array(strikers, dtype=int))

    @property
    def densities_kg_m3(self) -> np.ndarray:
        """(n_bodies,) each body's density ρ [kg/m³]."""
        return np.array([m.density_kg_m3 for m in self.materials])[self.material_ids]

    @property
    def masses_kg(self) -> np.ndarray:
        """(n_bodies,) masses [kg]: 3D spheres ρ π d³/6 of each body's material, sensor beads scaled."""
        return self.densities_kg_m3 * np.pi * self.diameters_m**3 / 6.0 * self.mass_factors

    @property
    def laws(self) -> ContactLaws:
        """The contact law of every pair of :attr:`materials` and of each against the wall
        (:mod:`hexdem.model.contact_law`)."""
        return ContactLaws.of(self.materials, self.wall, self.pair_damping, self.wall_damping, self.friction)

    @property
    def stiffness_table_pa(self) -> np.ndarray:
        """(K, K) k_n = (4/3) E* [Pa] of every pair of :attr:`materials`."""
        return self.laws.pair_table("normal_stiffness_pa")

    def contact_stiffness_pa(self, i, j) -> np.ndarray:
        r""":math:`k_n = \tfrac{4}{3} E^*` [Pa] of the contacts between bodies ``i`` and ``j``
        (arrays of indices): :math:`F = k_n \sqrt{R_\text{eff}}\, δ^{3/2}`."""
        ids = self.material_ids
        return self.stiffness_table_pa[ids[np.asarray(i, int)], ids[np.asarray(j, int)]]

    @property
    def uniform_contacts(self) -> bool:
        """Whether every bead–bead and striker contact has the same law (k_n and Mindlin's k_t: two
        materials of equal E* may differ in G*)."""
        present = np.ix_(np.unique(self.material_ids), np.unique(self.material_ids))
        laws = self.laws
        return all(
            bool(np.all(table == table.flat[0]))
            for table in (laws.pair_table(name)[present] for name in ("normal_stiffness_pa", "tangential_stiffness_pa"))
        )

    @property
    def mass_factors(self) -> np.ndarray:
        """(n_bodies,) mass of each body relative to a plain sphere of its size."""
        factors = np.ones(self.n_bodies)
        factors[list(self.sensor_beads)] = self.sensor_mass_factor
        return factors

    def wall_stiffness_pa(self, beads) -> np.ndarray:
        """k_n = (4/3) E* [Pa] of the contacts of ``beads`` (indices) with the walls, each bead's
        material against the wall's own E, ν."""
        if self.wall is None:
            raise HexdemError("this model has no walls")
        return self.laws.wall_table("normal_stiffness_pa")[self.material_ids[np.asarray(beads, int)]]

    @property
    def walls(self):
        return self.packing.walls if self.wall is not None else ()

    def impact_bodies(self) -> np.ndarray:
        """(n_impacts,) the body each impact sets moving: its striker, or its bead."""
        bodies, striker = self.struck_beads.copy(), len(self.packing)
        for k in self._striker_impacts:
            bodies[k], striker = striker, striker + 1
        return bodies

    def initial_positions_m(self) -> np.ndarray:
        """(n_bodies, 2) positions at t = 0 (the packed ones, moved by the initial state's
        displacements); each striker touches its bead, as packed, from outside."""
        pos = self.packing.positions_m
        beads, diameters = self.struck_beads, self.diameters_m
        strikers = [
            pos[beads[k]] - (diameters[beads[k]] + diameters[body]) / 2 * self.impacts[k].direction
            for body, k in enumerate(self._striker_impacts, start=len(self.packing))
        ]
        moved = pos if self.initial_state is None else pos + self.initial_state.displacements_m
        return np.vstack([moved, *strikers]) if strikers else moved.copy()

    def initial_velocities_m_s(self) -> np.ndarray:
        """(n_bodies, 2) velocities at t = 0: the initial state's, plus each impact's V0 on its
        striker, or on its bead."""
        vel = np.zeros((self.n_bodies, 2))
        if self.initial_state is not None:
            vel[: len(self.packing)] = self.initial_state.velocities_m_s
        for impact, body in zip(self.impacts, self.impact_bodies()):
            vel[body] += impact.speed_m_s * impact.direction
        return vel


@dataclass(frozen=True)
class RunSettings:
    """Time integration of one run: ``dt_s`` step [s], ``n_steps``, a sample every ``dump_every``
    steps; ``units`` is the system the engine works in and the results are reported in;
    ``sensor_every`` steps between two samples of the sensor particles (0: no sensors), a
    multiple of ``dump_every``; ``contact_time_s`` the impact's time scale [s] (the two-bead
    Hertz contact time at V0, or the precompressed contact's half period: see
    :func:`~hexdem.model.run_settings.contact_time_s`; 0 where a run was set up by hand)."""

    dt_s: float
    n_steps: int
    dump_every: int
    units: UnitSystem = SI
    sensor_every: int = 0
    contact_time_s: float = 0.0

    @property
    def duration_s(self) -> float:
        return self.dt_s * self.n_steps

    @property
    def n_samples(self) -> int:
        """Samples taken, t = 0 included (LAMMPS dumps every ``dump_every`` steps and at step 0)."""
        return self.n_steps // self.dump_every + 1
