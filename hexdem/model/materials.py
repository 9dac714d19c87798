r"""Elastic materials and the Hertz contact coefficients built from them (SI units).

Two spheres of diameter ``d`` and the same material touch with
:math:`F = A δ^{3/2}`, :math:`A = E \sqrt{d} / (3 (1 − ν^2))` (paper Sec. III,
:math:`V(r) = \tfrac{2}{5} A [d − r]_+^{5/2}`), and, for general radii,
:math:`F = \tfrac{4}{3} E^* \sqrt{R_\text{eff}}\, δ^{3/2}` with
:math:`1/E^* = (1 − ν_1^2)/E_1 + (1 − ν_2^2)/E_2` and :math:`1/R_\text{eff} = 1/R_1 + 1/R_2`. A sphere against a flat
wall is the limit R₂ → ∞ (R_eff = R₁), with the wall's own E and ν (the paper models the
delrin-lined walls as "spheres with an infinite radius").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypedDict

import numpy as np

from hexdem.errors import HexdemError


class MaterialTable(TypedDict, total=False):
    """A configuration's own material: its keys and their types (checked by
    :class:`~hexdem.model.config.RunConfig`)."""

    youngs_modulus_pa: float
    poisson_ratio: float
    density_kg_m3: float
    source: str


#: The numbers a material is made of; a configuration's own material gives them (and may add a ``source``).
MATERIAL_KEYS = tuple(key for key in MaterialTable.__annotations__ if key != "source")


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    Attributes: ``name``; ``youngs_modulus_pa`` E [Pa]; ``poisson_ratio`` ν [-];
    ``density_kg_m3`` ρ [kg/m³]; ``source`` where the values come from.
    """

    name: str
    youngs_modulus_pa: float
    poisson_ratio: float
    density_kg_m3: float
    source: str = ""

    def __post_init__(self):
        for key in MATERIAL_KEYS:
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
                raise HexdemError(f"material {self.name}: {key} must be a number, got {value!r}")
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

    @property
    def shear_compliance_per_pa(self) -> float:
        """(2 − ν)/G with G = E/(2(1 + ν)), this body's share of 1/G* (Mindlin) [1/Pa]."""
        return (2.0 - self.poisson_ratio) * 2.0 * (1.0 + self.poisson_ratio) / self.youngs_modulus_pa


#: Stainless steel type 316 as used in the paper's experiment (Sec. II).
STEEL_316 = Material(
    "steel316", youngs_modulus_pa=193e9, poisson_ratio=0.3, density_kg_m3=8000.0, source="the paper, Sec. II"
)
#: Delrin, the soft lining of the confining walls (Sec. II).
DELRIN = Material(
    "delrin", youngs_modulus_pa=3.1e9, poisson_ratio=0.35, density_kg_m3=1400.0, source="the paper, Sec. II"
)
#: Cartridge brass (C26000), typical handbook values.
BRASS = Material(
    "brass",
    youngs_modulus_pa=110e9,
    poisson_ratio=0.375,
    density_kg_m3=8530.0,
    source="C26000 cartridge brass, ASM handbook typical values",
)
#: Aluminium alloy 6061-T6, typical handbook values.
ALUMINIUM = Material(
    "aluminium",
    youngs_modulus_pa=68.9e9,
    poisson_ratio=0.33,
    density_kg_m3=2700.0,
    source="6061-T6, ASM handbook typical values",
)
#: Soda-lime glass, typical handbook values.
GLASS = Material(
    "glass",
    youngs_modulus_pa=72e9,
    poisson_ratio=0.22,
    density_kg_m3=2520.0,
    source="soda-lime glass, typical handbook values",
)
#: PTFE (Teflon) beads as measured for granular chains.
PTFE = Material(
    "ptfe",
    youngs_modulus_pa=1.46e9,
    poisson_ratio=0.46,
    density_kg_m3=2200.0,
    source="Daraio et al., Phys. Rev. E 72, 016603 (2005), Teflon beads",
)

MATERIALS = {m.name: m for m in (STEEL_316, DELRIN, BRASS, ALUMINIUM, GLASS, PTFE)}

#: Bead diameter of the experiment, d = 19.05 mm (3/4 inch).
PAPER_DIAMETER_M = 0.01905


def material(name: str, custom: dict | None = None) -> Material:
    """The material called ``name``: a preset (:data:`MATERIALS`) or one of ``custom``
    ({name: Material}, a configuration's own)."""
    known = {**MATERIALS, **(custom or {})}
    try:
        return known[name]
    except (KeyError, TypeError):
        raise HexdemError(f"unknown material {name!r}; known: {', '.join(known)}") from None


def custom_materials(table) -> dict[str, Material]:
    """{name: Material} of a configuration's ``materials`` table, {name: {youngs_modulus_pa,
    poisson_ratio, density_kg_m3[, source]}}; a preset's name cannot be redefined."""
    materials = {}
    for name, values in table.items():
        if name in MATERIALS or name == "none":
            raise HexdemError(f"material {name!r} is built in; give your own material another name")
        missing = sorted(set(MATERIAL_KEYS) - set(values))
        unknown = sorted(set(values) - {*MATERIAL_KEYS, "source"})
        if missing or unknown:
            raise HexdemError(
                f"material {name!r}: "
                + "; ".join(
                    ([f"missing {', '.join(missing)}"] if missing else [])
                    + ([f"unknown {', '.join(unknown)}"] if unknown else [])
                )
            )
        materials[name] = Material(name, **{"source": "this configuration", **values})
    return materials


def effective_modulus(a: Material, b: Material) -> float:
    """E* = 1/((1 − ν_a²)/E_a + (1 − ν_b²)/E_b) [Pa] of a Hertz contact between a and b."""
    return 1.0 / (a.compliance_per_pa + b.compliance_per_pa)


def effective_shear_modulus(a: Material, b: Material) -> float:
    """G* = 1/((2 − ν_a)/G_a + (2 − ν_b)/G_b) [Pa] of a Mindlin contact between a and b."""
    return 1.0 / (a.shear_compliance_per_pa + b.shear_compliance_per_pa)


def mindlin_stiffness(a: Material, b: Material) -> float:
    """k_t = 8 G* [Pa]: Mindlin's no-slip tangential stiffness is k_t a for a contact of radius a
    (against the normal 2 E* a), the ``k_t`` of LAMMPS's ``tangential mindlin``, which multiplies
    it by the contact radius."""
    return 8.0 * effective_shear_modulus(a, b)


def hertz_stiffness(a: Material, b: Material) -> float:
    r""":math:`k_n = \tfrac{4}{3} E^*` [Pa]: the Hertz prefactor with
    :math:`F = k_n \sqrt{R_\text{eff}}\, δ^{3/2}`.

    This is the ``k_n`` of LAMMPS's ``pair_style granular`` / ``fix wall/gran`` ``hertz``
    model, which computes :math:`F = k_n \sqrt{R_\text{eff} δ}\, δ`.
    """
    return 4.0 / 3.0 * effective_modulus(a, b)


def hertz_coefficient(diameter_m, mat: Material = STEEL_316):
    r""":math:`A = E \sqrt{d} / (3 (1 − ν^2))` [:math:`\mathrm{N/m^{1.5}}`] for two equal spheres of
    one material."""
    return hertz_stiffness(mat, mat) * np.sqrt(np.asarray(diameter_m) / 4.0)


def sphere_mass(diameter_m, mat: Material = STEEL_316):
    """M = ρ π d³ / 6 [kg]: the 3D sphere mass, also in the 2D model."""
    return mat.density_kg_m3 * np.pi * np.asarray(diameter_m) ** 3 / 6.0
