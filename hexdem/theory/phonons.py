r"""Linear waves of the precompressed hexagonal packing: phonon bands, the Dirac point at K.

About a static contact force f0 every contact is a spring of stiffness
:math:`k = \tfrac{3}{2} A^{2/3} f_0^{1/3}`
(:func:`~hexdem.model.precompression.spring_stiffness`); the beads of mass m sit on a triangular
lattice of spacing a = d − δ0. Each bead has two displacement components, so a plane wave
:math:`u ∝ e^{i(q \cdot x − ωt)}` gives two bands, the eigenvalues ω² of the dynamical matrix

.. math::

    D(q) = \frac{k}{m} \sum_j (1 − \cos q \cdot a_j)\, e_j e_j^T,

the sum over the six neighbours at a_j = a e_j (the bonds at 30°, 90°, 150°, … from +x in the
paper's labels). The static force's transverse (geometric) stiffness, −f0/a, is left out: it is
δ0/(1.5 a) of k, below 1e-3 up to f0 = 100 N for the paper's steel beads.

**By hand** (the tests check them):

* Γ (q = 0): ω = 0 twice; near it ω = c q with c_L = sqrt(9/8) a sqrt(k/m) and
  c_T = sqrt(3/8) a sqrt(k/m) (Lamé constants λ = μ = (√3/4) k).
* K (a corner of the Brillouin zone, q·a_j = ±2π/3 for every bond): 1 − cos = 3/2 for all six,
  and Σ_j e_j e_jᵀ = 3 I, so D = (9/2)(k/m) I: ω_K = sqrt(9/2) sqrt(k/m), twice. Near K the
  first-order term (k/m) √3 a Σ_j (q·e_j) e_j e_jᵀ, over the three bonds at phase +2π/3 (30°, 150°
  and 270°), is traceless with eigenvalues
  ±(3/4)(k/m) √3 a |q| in every direction: the bands meet in a cone,
  ω = ω_K ± v_D |q − K|, v_D = (√6/8) a sqrt(k/m) (:func:`cone_slope`).
* M (the middle of a zone edge, next to K): two bond directions have q·a_j = π, the third 0, so
  D = 4 (k/m)(e_A e_Aᵀ + e_B e_Bᵀ) with e_A, e_B 60° apart: ω_M = sqrt(6 k/m) and sqrt(2 k/m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.materials import STEEL_316, Material, hertz_coefficient, sphere_mass
from hexdem.model.precompression import spring_stiffness, static_overlap

#: The band structure's path through the Brillouin zone.
PATH = ("Γ", "K", "M", "Γ")
#: Unit vectors of the three bond directions (their opposites are the other three neighbours).
BOND_DIRECTIONS = np.array(
    [[math.cos(math.radians(angle)), math.sin(math.radians(angle))] for angle in (30.0, 90.0, 150.0)]
)


@dataclass(frozen=True)
class Lattice2D:
    """The linear triangular lattice: ``spacing_m`` a, ``stiffness_n_m`` k, ``mass_kg`` m."""

    spacing_m: float
    stiffness_n_m: float
    mass_kg: float

    @classmethod
    def precompressed(cls, force_n: float, diameter_m: float, material: Material = STEEL_316) -> Lattice2D:
        """The packing of ``material`` spheres of ``diameter_m`` with every contact at ``force_n`` > 0
        (an uncompressed packing has no linear waves)."""
        if not force_n > 0:
            raise HexdemError(f"linear waves need a precompression > 0 N per contact, got {force_n!r}")
        coefficient = float(hertz_coefficient(diameter_m, material))
        return cls(
            diameter_m - static_overlap(force_n, coefficient),
            spring_stiffness(force_n, coefficient),
            float(sphere_mass(diameter_m, material)),
        )

    @classmethod
    def of(cls, config) -> Lattice2D:
        """The packing of a :class:`~hexdem.model.config.RunConfig` (its beads' material and size,
        its ``precompression_n``)."""
        return cls.precompressed(config.precompression_n, config.diameter_m, config.material(config.bead_material))

    @property
    def frequency_scale(self) -> float:
        """sqrt(k/m) [rad/s]."""
        return math.sqrt(self.stiffness_n_m / self.mass_kg)

    def high_symmetry_points(self) -> dict[str, np.ndarray]:
        """Γ, K and M [1/m] of the Brillouin zone: K = (0, 4π/(3a)), at 90°, where q·a e_j = ±2π/3
        (mod 2π, cos = −1/2) for every bond; M = (π/(√3 a), π/a), at 60°, the middle of the zone
        edge next to K (|K − M| = 2π/(3a)): half the reciprocal vector perpendicular to the
        150° bonds."""
        a = self.spacing_m
        return {
            "Γ": np.zeros(2),
            "K": np.array([0.0, 4 * math.pi / (3 * a)]),
            "M": np.array([math.pi / (math.sqrt(3) * a), math.pi / a]),
        }

    def dirac_frequency(self) -> float:
        """ω_K = sqrt(9/2) sqrt(k/m) [rad/s], where the two bands meet (module docstring)."""
        return math.sqrt(4.5) * self.frequency_scale


def dynamical_matrix(lattice: Lattice2D, q) -> np.ndarray:
    """D(q) [rad²/s²] (..., 2, 2) of the module docstring at the wave vectors ``q`` (..., 2)."""
    q = np.asarray(q, float)
    phases = lattice.spacing_m * q @ BOND_DIRECTIONS.T
    weights = 4 * np.sin(phases / 2) ** 2  # 2 (1 − cos): each direction and its opposite, exact at small q
    return lattice.frequency_scale**2 * np.einsum("...j,ja,jb->...ab", weights, BOND_DIRECTIONS, BOND_DIRECTIONS)


def frequencies(lattice: Lattice2D, q) -> np.ndarray:
    """The two band frequencies ω [rad/s] (..., 2) at the wave vectors ``q`` (..., 2), ascending."""
    return np.sqrt(np.clip(np.linalg.eigvalsh(dynamical_matrix(lattice, q)), 0.0, None))


def cone_slope(lattice: Lattice2D) -> float:
    """v_D = (√6/8) a sqrt(k/m) [m/s], the Dirac cone's slope at K."""
    return math.sqrt(6) / 8 * lattice.spacing_m * lattice.frequency_scale


def sound_speeds(lattice: Lattice2D) -> tuple[float, float]:
    """(c_L, c_T) = (sqrt(9/8), sqrt(3/8)) a sqrt(k/m) [m/s]."""
    scale = lattice.spacing_m * lattice.frequency_scale
    return math.sqrt(9 / 8) * scale, math.sqrt(3 / 8) * scale


def band_path(lattice: Lattice2D, points_per_segment: int = 60) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(path position [1/m] (P,), wave vectors (P, 2), frequencies [rad/s] (P, 2)) along
    :data:`PATH`, ``points_per_segment`` per segment, the corners included once."""
    corners = [lattice.high_symmetry_points()[name] for name in PATH]
    vectors = [corners[0]]
    for start, end in zip(corners[:-1], corners[1:]):
        steps = np.linspace(0.0, 1.0, points_per_segment + 1)[1:, None]
        vectors.extend(start + steps * (end - start))
    vectors = np.array(vectors)
    position = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(vectors, axis=0), axis=1))])
    return position, vectors, np.array([frequencies(lattice, q) for q in vectors])
