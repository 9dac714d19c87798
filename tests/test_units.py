"""Materials and the paper's nondimensional scaling (eq. scaling): A = d = M = 1 both ways."""

import numpy as np
import pytest
from conftest import contact_of

from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.hertz import contact_time
from hexdem.model.materials import (
    DELRIN,
    MATERIALS,
    STEEL_316,
    Material,
    effective_modulus,
    hertz_coefficient,
    sphere_mass,
)
from hexdem.model.model_builder import build_model
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


def test_every_preset_material_is_physical_and_sourced():
    assert {"steel316", "delrin", "brass", "aluminium", "glass", "ptfe"} <= set(MATERIALS)
    for mat in MATERIALS.values():
        assert mat.source and 1e9 <= mat.youngs_modulus_pa <= 3e11 and 0 < mat.poisson_ratio < 0.5
        assert 1000 <= mat.density_kg_m3 <= 9000


@pytest.mark.parametrize("name", ["brass", "ptfe"])
def test_a_packing_of_another_material_takes_its_hertz_law_and_mass(name):
    """The contact time τ = 2.9432 δ_max / V, δ_max = (5 μ V² / (4 A))^{2/5}, of two beads: μ = M/2,
    A = E sqrt(d)/(3(1 − ν²)), M = ρ π d³/6, written out from the material's E, ν, ρ."""
    mat = MATERIALS[name]
    mass = mat.density_kg_m3 * np.pi * D**3 / 6
    a = mat.youngs_modulus_pa * np.sqrt(D) / (3 * (1 - mat.poisson_ratio**2))
    config = RunConfig(bead_material=name, edge_beads=3)
    assert contact_of(config) == pytest.approx(contact_time(mass / 2, a, 0.4), rel=1e-12)
    assert contact_of(config) == pytest.approx(2.9432 * (5 * mass / 2 * 0.4**2 / (4 * a)) ** 0.4 / 0.4, rel=1e-4)
    assert build_model(config).masses_kg[0] == pytest.approx(mass)


def test_a_configuration_defines_its_own_material():
    table = {"bronze": {"youngs_modulus_pa": 1.2e11, "poisson_ratio": 0.34, "density_kg_m3": 8800.0}}
    model = build_model(RunConfig(bead_material="bronze", materials=table, edge_beads=3))
    assert model.bead == Material("bronze", 1.2e11, 0.34, 8800.0, "this configuration")
    with pytest.raises(HexdemError, match="built in"):
        RunConfig(materials={"brass": table["bronze"]})
    with pytest.raises(HexdemError, match="missing density_kg_m3"):
        RunConfig(bead_material="bronze", materials={"bronze": {"youngs_modulus_pa": 1e11, "poisson_ratio": 0.3}})
