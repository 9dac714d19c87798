"""The contacts of a :class:`~hexdem.model.granular.GranularModel` as the reference kernels need them:
Hertz coefficients in the run's units, the law of any pair of bodies that the neighbour search
lists (:mod:`hexdem.engines.reference.neighbours`), the walls' geometry."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from hexdem.engines.reference.neighbours import REBUILD_SHARE, candidate_pairs, carried_over, skin_of
from hexdem.model.granular import GranularModel
from hexdem.model.units import UnitSystem
from hexdem.model.walls import wall_normals


def coefficient(stiffness_pa, r_eff_m, units: UnitSystem):
    r""":math:`k \sqrt{R_\text{eff}}` [:math:`\mathrm{N/m^{1.5}}`] of a contact in ``units``: Hertz's
    :math:`A = k_n \sqrt{R_\text{eff}}`, or Mindlin's :math:`k_t \sqrt{R_\text{eff}}` (whose force
    :math:`k_t a ξ = k_t \sqrt{R_\text{eff}} \sqrt{δ}\, ξ` has the same units)."""
    return stiffness_pa * np.sqrt(r_eff_m) * units.length_m**1.5 / units.force_n


def reduced(a, b):
    """a b / (a + b): the reduced radius or mass of two bodies."""
    return a * b / (a + b)


@dataclass(frozen=True)
class PairLaws:
    """What the contact law of any pair of bodies (i, j) takes, beads and strikers alike.

    Per body: ``start`` (n, 2) positions at t = 0 and ``radii`` (n,) in ``units``' length,
    ``radii_m`` [m], ``masses`` (n,) in ``units``' mass, ``material_ids``. Per pair of materials
    (K, K): ``normal_pa`` k_n, ``damping`` Tsuji's α, ``tangential_pa`` Mindlin's k_t, ``friction`` μ.
    """

    start: np.ndarray
    radii: np.ndarray
    radii_m: np.ndarray
    masses: np.ndarray
    material_ids: np.ndarray
    normal_pa: np.ndarray
    damping: np.ndarray
    tangential_pa: np.ndarray
    friction: np.ndarray
    units: UnitSystem

    @classmethod
    def of(cls, model: GranularModel, units: UnitSystem) -> PairLaws:
        laws, radii_m = model.laws, model.diameters_m / 2
        return cls(
            model.initial_positions_m() / units.length_m,
            radii_m / units.length_m,
            radii_m,
            model.masses_kg / units.mass_kg,
            model.material_ids,
            laws.pair_table("normal_stiffness_pa"),
            laws.pair_table("damping"),
            laws.pair_table("tangential_stiffness_pa"),
            laws.pair_table("friction"),
            units,
        )

    def normal(self, i, j):
        """(rest_x, rest_y, c, A, η) of the pairs (i → j): rest vector of their positions at t = 0,
        contact distance c = R_i + R_j, Hertz's A = k_n sqrt(R_eff), Tsuji's η = α sqrt(m_eff A)."""
        ids, radii = self.material_ids, self.radii_m
        rest = self.start[j] - self.start[i]
        stiffness = coefficient(self.normal_pa[ids[i], ids[j]], reduced(radii[i], radii[j]), self.units)
        damping = self.damping[ids[i], ids[j]] * np.sqrt(reduced(self.masses[i], self.masses[j]) * stiffness)
        return (rest[:, 0].copy(), rest[:, 1].copy(), (radii[i] + radii[j]) / self.units.length_m, stiffness, damping)

    def tangential(self, i, j):
        """(K, μ, R_i, R_j) of the pairs (i → j): Mindlin's K = k_t sqrt(R_eff), Coulomb's μ, the radii."""
        ids, radii = self.material_ids, self.radii_m
        stiffness = coefficient(self.tangential_pa[ids[i], ids[j]], reduced(radii[i], radii[j]), self.units)
        return stiffness, self.friction[ids[i], ids[j]], self.radii[i], self.radii[j]


def wall_geometry(model: GranularModel):
    """(beads, inward normals (K, 2), rest gaps [m], curvatures [1/m], R_eff [m]) of every wall
    member: n the inward normal at the bead's rest position (its position at t = 0), curvature 1/ρ
    with ρ the distance from there to a curved wall's centre (0 for a plane), R_eff the Hertz
    contact radius."""
    lattice, walls = model.packing, model.walls
    positions, radii = model.initial_positions_m()[: len(lattice)], lattice.radii_m
    beads, normals = wall_normals(walls, positions)
    gaps = np.concatenate([np.zeros(0)] + [wall.gaps_m(positions[wall.members], radii[wall.members]) for wall in walls])
    curvature = np.concatenate([np.zeros(0)] + [wall.curvatures_at(positions[wall.members]) for wall in walls])
    r_eff = np.concatenate([np.zeros(0)] + [wall.contact_radii_m(radii[wall.members]) for wall in walls])
    return beads, normals, gaps, curvature, r_eff


@dataclass
class ListedPairs:
    """The contacts of a run under way: a kernel's arrays for the neighbour list of the moment,
    rebuilt as the bodies move (:mod:`hexdem.engines.reference.neighbours`).

    ``kernel`` the kernel's NamedTuple: its pairs ``pair_i``, ``pair_j`` (i < j) with their laws,
    ``built_x``, ``built_y`` the displacements at the list's build and ``reach`` how far a body may
    move from there; ``laws`` the laws of any pair; ``fields(i, j)`` the kernel's per-pair fields of
    the pairs (i → j) besides ``pair_i``, ``pair_j``, as a dict; ``skin`` in the run's length unit;
    ``builds`` the lists built so far; ``carried`` per-pair arrays of the run under way that every
    rebuild carries over by the pairs' (i, j) keys (the frictional kernel's tangential histories ξ).
    """

    kernel: tuple | None
    laws: PairLaws
    fields: Callable[[np.ndarray, np.ndarray], dict]
    skin: float
    builds: int = 0
    carried: dict = field(default_factory=dict)

    @classmethod
    def at_rest(cls, laws: PairLaws, fields, make_kernel) -> ListedPairs:
        """The list of the bodies at t = 0, in the kernel that ``make_kernel(**list_fields)`` makes."""
        listed = cls(None, laws, fields, skin_of(2.0 * laws.radii))
        at_rest = np.zeros(len(laws.radii))
        listed.kernel = make_kernel(**listed.fields_at(at_rest, at_rest))
        return listed

    @property
    def n_pairs(self) -> int:
        """Pairs in the neighbour list of the moment."""
        return len(self.kernel.pair_i)

    def fields_at(self, x, y) -> dict:
        """The kernel's fields of the list of the pairs whose gap is below the skin at the
        displacements (x, y) (from t = 0)."""
        pairs = candidate_pairs(self.laws.start + np.column_stack([x, y]), self.laws.radii, self.skin)
        i, j = pairs[:, 0].copy(), pairs[:, 1].copy()
        self.builds += 1
        return dict(
            pair_i=i,
            pair_j=j,
            **self.fields(i, j),
            built_x=np.array(x, float),
            built_y=np.array(y, float),
            reach=REBUILD_SHARE * self.skin,
        )

    def rebuild(self, x, y) -> None:
        """Rebuild the list at the displacements (x, y), carrying the ``carried`` arrays over."""
        old = np.column_stack([self.kernel.pair_i, self.kernel.pair_j])
        self.kernel = self.kernel._replace(**self.fields_at(x, y))
        new = np.column_stack([self.kernel.pair_i, self.kernel.pair_j])
        self.carried = {name: carried_over(old, values, new) for name, values in self.carried.items()}

    def advance(self, steps: int, integrate, x, y) -> None:
        """Do ``steps`` steps of ``integrate(kernel, n)`` (the kernel's, on the state whose
        displacements are (x, y)), rebuilding the list wherever it stopped because it went stale;
        stop early where the displacements are no longer finite."""
        done = integrate(self.kernel, steps)
        while done < steps:
            if not (np.isfinite(x).all() and np.isfinite(y).all()):
                return  # diverged: nothing to list; the engine reports it
            self.rebuild(x, y)
            done += integrate(self.kernel, steps - done)
