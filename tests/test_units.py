"""Materials and the paper's nondimensional scaling (eq. scaling): A = d = M = 1 both ways."""

import numpy as np
import pytest

from hexdem.errors import HexdemError
from hexdem.model.materials import DELRIN, STEEL_316, Material, effective_modulus, hertz_coefficient, sphere_mass
from hexdem.model.units import nondimensional, to_nondimensional_velocity, to_physical_velocity

D = 0.01905


def test_nondimensional_units_make_a_d_m_unity():
    units = nondimensional(D, STEEL_316)
    a = hertz_coefficient(D, STEEL_316)
    assert units.length_m == D
    assert sphere_mass(D, STEEL_316) / units.mass_kg == pytest.approx(1.0)
    assert a / (units.force_n / units.length_m**1.5) == pytest.approx(1.0)


def test_velocity_rule_of_the_paper():
    """Replace V by V sqrt(M/A) / d^(5/4) (end of Sec. V), and back."""
    m, a = sphere_mass(D, STEEL_316), hertz_coefficient(D, STEEL_316)
    assert to_nondimensional_velocity(0.4, D) == pytest.approx(0.4 * np.sqrt(m / a) / D**1.25)
    assert to_physical_velocity(to_nondimensional_velocity(0.7, D), D) == pytest.approx(0.7)


def test_hertz_coefficient_matches_the_two_sphere_hertz_law():
    """A = (4/3) E* sqrt(R_eff), E* = E / (2 (1 - nu^2)), R_eff = d/4  ->  A = E sqrt(d) / (3 (1 - nu^2))."""
    e, nu = STEEL_316.youngs_modulus_pa, STEEL_316.poisson_ratio
    assert hertz_coefficient(D) == pytest.approx(e * np.sqrt(D) / (3 * (1 - nu**2)))
    assert effective_modulus(STEEL_316, DELRIN) < DELRIN.youngs_modulus_pa / (1 - DELRIN.poisson_ratio**2)


def test_bad_material_values():
    with pytest.raises(HexdemError, match="Poisson"):
        Material("rubberish", 1e6, 0.6, 1000.0)

