"""Elastic materials and the Hertz contact coefficients built from them (SI units).

Two spheres of diameter ``d`` and the same material touch with
F = A δ^{3/2},  A = E sqrt(d) / (3 (1 − ν²))     (paper Sec. III, V(r) = (2/5) A [d − r]_+^{5/2}),
and, for general radii, F = (4/3) E* sqrt(R_eff) δ^{3/2} with
1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ and 1/R_eff = 1/R₁ + 1/R₂. A sphere against a flat
wall is the limit R₂ → ∞ (R_eff = R₁), with the wall's own E and ν (the paper models the
delrin-lined walls as "spheres with an infinite radius").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    Attributes: ``name``; ``youngs_modulus_pa`` E [Pa]; ``poisson_ratio`` ν [-];
    ``density_kg_m3`` ρ [kg/m³].
    """

    name: str
    youngs_modulus_pa: float
    poisson_ratio: float
    density_kg_m3: float

    def __post_init__(self):
        if not self.youngs_modulus_pa > 0:
            raise HexdemError(f"material {self.name}: Young's modulus must be > 0 Pa")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise HexdemError(f"material {self.name}: Poisson ratio must lie in (-1, 0.5)")
        if not self.density_kg_m3 > 0:
            raise HexdemError(f"material {self.name}: density must be > 0 kg/m^3")

    @property
    def compliance_per_pa(self) -> float:
        """(1 − ν²)/E, this body's share of 1/E* [1/Pa]."""
        return (1.0 - self.poisson_ratio**2) / self.youngs_modulus_pa


#: Stainless steel type 316 as used in the paper's experiment (Sec. II).
STEEL_316 = Material("steel316", youngs_modulus_pa=193e9, poisson_ratio=0.3, density_kg_m3=8000.0)
#: Delrin, the soft lining of the confining walls (Sec. II).
DELRIN = Material("delrin", youngs_modulus_pa=3.1e9, poisson_ratio=0.35, density_kg_m3=1400.0)

MATERIALS = {m.name: m for m in (STEEL_316, DELRIN)}

#: Bead diameter of the experiment, d = 19.05 mm (3/4 inch).
PAPER_DIAMETER_M = 0.01905


def material(name: str) -> Material:
    """Look up a preset material by name (``steel316`` or ``delrin``)."""
    try:
        return MATERIALS[name]
    except KeyError:
        raise HexdemError(f"unknown material {name!r}; known: {', '.join(MATERIALS)}") from None


def effective_modulus(a: Material, b: Material) -> float:
    """E* = 1/((1 − ν_a²)/E_a + (1 − ν_b²)/E_b) [Pa] of a Hertz contact between a and b."""
    return 1.0 / (a.compliance_per_pa + b.compliance_per_pa)


def hertz_stiffness(a: Material, b: Material) -> float:
    """k_n = (4/3) E* [Pa]: the Hertz prefactor with F = k_n sqrt(R_eff) δ^{3/2}.

    This is the ``k_n`` of LAMMPS's ``pair_style granular`` / ``fix wall/gran`` ``hertz``
    model, which computes F = k_n sqrt(R_eff δ) δ.
    """
    return 4.0 / 3.0 * effective_modulus(a, b)


def hertz_coefficient(diameter_m, mat: Material = STEEL_316):
    """A = E sqrt(d) / (3 (1 − ν²)) [N/m^1.5] for two equal spheres of one material."""
    return hertz_stiffness(mat, mat) * np.sqrt(np.asarray(diameter_m) / 4.0)


def sphere_mass(diameter_m, mat: Material = STEEL_316):
    """M = ρ π d³ / 6 [kg]: the 3D sphere mass, also in the 2D model."""
    return mat.density_kg_m3 * np.pi * np.asarray(diameter_m) ** 3 / 6.0
