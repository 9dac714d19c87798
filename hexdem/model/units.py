r"""The paper's nondimensional scaling, eq. (3), and conversions both ways.

With A = d = M = 1 inside the theory, lengths are measured in d, masses in M and times in
:math:`T = \sqrt{M / (A d^{1/2})}`; velocities are then measured in
:math:`d/T = d^{5/4} \sqrt{A/M}`, which is the paper's rule "replace V by
:math:`V \sqrt{M/A} / d^{5/4}`" (end of Sec. V).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.model.materials import STEEL_316, Material, hertz_coefficient, sphere_mass


@dataclass(frozen=True)
class UnitSystem:
    """Scales of one unit system expressed in SI: a quantity q in this system is q_SI / scale.

    ``length_m``, ``mass_kg``, ``time_s`` are the units; ``name`` is ``"si"`` or
    ``"nondimensional"``; ``lammps_units`` the matching LAMMPS ``units`` style.
    """

    name: str
    length_m: float = 1.0
    mass_kg: float = 1.0
    time_s: float = 1.0

    @property
    def lammps_units(self) -> str:
        return "si" if self.name == "si" else "lj"

    @property
    def velocity_m_s(self) -> float:
        return self.length_m / self.time_s

    @property
    def force_n(self) -> float:
        return self.mass_kg * self.length_m / self.time_s**2

    @property
    def stress_pa(self) -> float:
        return self.force_n / self.length_m**2

    @property
    def density_kg_m3(self) -> float:
        return self.mass_kg / self.length_m**3


SI = UnitSystem("si")


def nondimensional(diameter_m: float, mat: Material = STEEL_316) -> UnitSystem:
    """The paper's system A = d = M = 1 for beads of ``diameter_m`` made of ``mat``."""
    a = float(hertz_coefficient(diameter_m, mat))
    m = float(sphere_mass(diameter_m, mat))
    return UnitSystem(
        "nondimensional", length_m=diameter_m, mass_kg=m, time_s=float(np.sqrt(m / (a * np.sqrt(diameter_m))))
    )


def to_nondimensional_velocity(v_m_s, diameter_m: float, mat: Material = STEEL_316):
    r""":math:`V \sqrt{M/A} / d^{5/4}`: a physical velocity in the paper's units."""
    return np.asarray(v_m_s) / nondimensional(diameter_m, mat).velocity_m_s


def to_physical_velocity(v, diameter_m: float, mat: Material = STEEL_316):
    """The inverse of :func:`to_nondimensional_velocity` [m/s]."""
    return np.asarray(v) * nondimensional(diameter_m, mat).velocity_m_s


def in_si(values: np.ndarray, unit: float) -> np.ndarray:
    """``values`` in units of ``unit`` SI units, in SI: the array itself for SI units (× 1 is exact)."""
    return values if unit == 1.0 else values * unit
