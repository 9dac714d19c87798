"""The physical model shared by every engine: packing + materials + impact, in SI units.

A :class:`GranularModel` says everything an engine needs to integrate the paper's
Hamiltonian (Sec. III): bead masses, Hertz stiffnesses of bead–bead and bead–wall
contacts, the walls, and the initial state. The optional striker is an extra body (the
last one), a sphere of the bead material and nominal diameter that touches the struck
bead at t = 0 and moves towards it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.common.checks import is_number
from hexdem.errors import HexdemError
from hexdem.model.dissipation import check_restitution, damping_coefficient
from hexdem.model.lattice import Lattice, strike_direction
from hexdem.model.materials import DELRIN, STEEL_316, Material, hertz_stiffness
from hexdem.model.units import SI, UnitSystem


@dataclass(frozen=True)
class Impact:
    """How the packing is struck.

    ``speed_m_s`` V0 > 0 [m/s]; ``angle_deg`` strike angle from +x; ``striker`` False:
    V0 is given to the struck bead (the paper's numerics); True: a striker sphere moving
    at V0 hits it (the experiment).
    """

    speed_m_s: float
    angle_deg: float = 0.0
    striker: bool = False

    def __post_init__(self):
        if not (is_number(self.speed_m_s) and self.speed_m_s > 0):
            raise HexdemError(f"impact velocity V0 must be > 0 (towards the packing), got {self.speed_m_s}")
        strike_direction(self.angle_deg)

    @property
    def direction(self) -> np.ndarray:
        return strike_direction(self.angle_deg)


@dataclass(frozen=True)
class GranularModel:
    """Lattice, materials and impact of one simulation (SI units).

    ``wall`` is the wall-lining material, or None for a packing without walls;
    ``restitution`` and ``wall_restitution`` the coefficients of restitution of bead–bead and
    bead–wall contacts (1: the paper's conservative model; below 1: Tsuji damping, see
    :mod:`hexdem.model.dissipation`); ``held_force_n`` a constant force (fx, fy) [N] on the
    struck bead, the force its missing wall would exert on a precompressed packing
    (:mod:`hexdem.model.precompression`); ``sensor_beads`` bead indices of the sensor particles,
    whose mass is ``sensor_mass_factor`` times a plain bead's (the accelerometer inside).

    Materials: bead material id 0 is ``bead``, ids 1, 2, … are ``extra_materials`` (the
    lattice's ``material_ids`` say which bead is which); the striker is of ``striker_material``
    (None: ``bead``) and of diameter ``striker_diameter_m`` (None: the nominal d). Every
    contact is Hertz's with the pair's own E* and R_eff (:meth:`contact_stiffness_pa`).
    """

    lattice: Lattice
    impact: Impact
    bead: Material = STEEL_316
    wall: Material | None = DELRIN
    restitution: float = 1.0
    wall_restitution: float = 1.0
    held_force_n: tuple[float, float] = (0.0, 0.0)
    sensor_beads: tuple[int, ...] = ()
    sensor_mass_factor: float = 1.0
    extra_materials: tuple[Material, ...] = ()
    striker_material: Material | None = None
    striker_diameter_m: float | None = None

    def __post_init__(self):
        check_restitution("restitution", self.restitution)
        check_restitution("wall_restitution", self.wall_restitution)
        if not (is_number(self.sensor_mass_factor) and self.sensor_mass_factor > 0):
            raise HexdemError(f"sensor_mass_factor must be > 0, got {self.sensor_mass_factor!r}")
        if len(self.lattice) and self.lattice.material_ids.max() > len(self.extra_materials):
            raise HexdemError(f"bead material id {self.lattice.material_ids.max()} has no material "
                              f"({1 + len(self.extra_materials)} given)")
        if self.striker_diameter_m is not None and not (is_number(self.striker_diameter_m) and self.striker_diameter_m > 0):
            raise HexdemError(f"striker diameter must be > 0 m, got {self.striker_diameter_m!r}")

    @property
    def dissipative(self) -> bool:
        return self.restitution < 1.0 or (bool(self.walls) and self.wall_restitution < 1.0)

    def external_forces_n(self) -> np.ndarray:
        """(n_bodies, 2) constant forces [N] on the bodies: the held force on the struck bead."""
        forces = np.zeros((self.n_bodies, 2))
        forces[self.lattice.struck] = self.held_force_n
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
        return self.impact.striker

    @property
    def n_bodies(self) -> int:
        """Beads plus the striker, if any (the striker is the last body)."""
        return len(self.lattice) + int(self.has_striker)

    @property
    def diameters_m(self) -> np.ndarray:
        extra = [self.striker_diameter_m or self.lattice.diameter_m] if self.has_striker else []
        return np.concatenate([self.lattice.diameters_m, extra])

    @property
    def materials(self) -> tuple[Material, ...]:
        """Materials by id: the beads' (``bead``, then ``extra_materials``), then the striker's
        if it has its own."""
        striker = (self.striker_material,) if self.striker_material is not None else ()
        return (self.bead, *self.extra_materials, *striker)

    @property
    def material_ids(self) -> np.ndarray:
        """(n_bodies,) each body's index into :attr:`materials`."""
        if not self.has_striker:
            return self.lattice.material_ids
        striker = len(self.materials) - 1 if self.striker_material is not None else 0
        return np.append(self.lattice.material_ids, striker)

    @property
    def densities_kg_m3(self) -> np.ndarray:
        """(n_bodies,) each body's density ρ [kg/m³]."""
        return np.array([m.density_kg_m3 for m in self.materials])[self.material_ids]

    @property
    def masses_kg(self) -> np.ndarray:
        """(n_bodies,) masses [kg]: 3D spheres ρ π d³/6 of each body's material, sensor beads scaled."""
        return self.densities_kg_m3 * np.pi * self.diameters_m**3 / 6.0 * self.mass_factors

    @property
    def stiffness_table_pa(self) -> np.ndarray:
        """(K, K) k_n = (4/3) E* [Pa] of every pair of :attr:`materials`."""
        return np.array([[hertz_stiffness(a, b) for b in self.materials] for a in self.materials])

    def contact_stiffness_pa(self, i, j) -> np.ndarray:
        """k_n = (4/3) E* [Pa] of the contacts between bodies ``i`` and ``j`` (arrays of indices):
        F = k_n sqrt(R_eff) δ^{3/2}."""
        ids = self.material_ids
        return self.stiffness_table_pa[ids[np.asarray(i, int)], ids[np.asarray(j, int)]]

    @property
    def uniform_contacts(self) -> bool:
        """Whether every bead–bead and striker contact has the same k_n (one material)."""
        table = self.stiffness_table_pa[np.ix_(np.unique(self.material_ids), np.unique(self.material_ids))]
        return bool(np.all(table == table.flat[0]))

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
        table = np.array([hertz_stiffness(m, self.wall) for m in self.materials])
        return table[self.material_ids[np.asarray(beads, int)]]

    @property
    def walls(self):
        return self.lattice.walls if self.wall is not None else ()

    def initial_positions_m(self) -> np.ndarray:
        """(n_bodies, 2) positions at t = 0; a striker touches the struck bead from outside."""
        pos = self.lattice.positions_m
        if not self.has_striker:
            return pos.copy()
        struck = self.lattice.struck
        gap = (self.lattice.diameters_m[struck] + self.diameters_m[-1]) / 2
        return np.vstack([pos, pos[struck] - gap * self.impact.direction])

    def initial_velocities_m_s(self) -> np.ndarray:
        """(n_bodies, 2) velocities at t = 0: V0 on the striker, or on the struck bead."""
        vel = np.zeros((self.n_bodies, 2))
        vel[-1 if self.has_striker else self.lattice.struck] = self.impact.speed_m_s * self.impact.direction
        return vel


@dataclass(frozen=True)
class RunSettings:
    """Time integration of one run: ``dt_s`` step [s], ``n_steps``, a sample every ``dump_every``
    steps; ``units`` is the system the engine works in and the results are reported in;
    ``sensor_every`` steps between two samples of the sensor particles (0: no sensors), a
    multiple of ``dump_every``; ``contact_time_s`` the impact's time scale [s] (the two-bead
    Hertz contact time at V0, or the precompressed contact's half period: see
    :meth:`~hexdem.model.config.RunConfig.contact_time_s`; 0 where a run was set up by hand)."""

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
