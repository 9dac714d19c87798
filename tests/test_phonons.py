"""The precompressed lattice's linear bands, against what the module derives by hand: Γ, K
and M, the degeneracy at K and its cone's slope, the long-wave sound speeds."""

import math

import numpy as np
import pytest

from hexdem.errors import HexdemError
from hexdem.model.materials import hertz_coefficient, sphere_mass
from hexdem.model.precompression import longitudinal_sound_speed, spring_stiffness, static_overlap
from hexdem.theory.phonons import Lattice2D, band_path, cone_slope, dynamical_matrix, frequencies, sound_speeds

LATTICE = Lattice2D.precompressed(20.0, 0.01905)
SCALE = LATTICE.frequency_scale


def test_the_lattice_is_the_precompressed_packings():
    """a = d − δ0, k = (3/2) A^(2/3) f0^(1/3), m = πρd³/6 (hexdem.model.precompression)."""
    coefficient = float(hertz_coefficient(0.01905))
    assert LATTICE.spacing_m == pytest.approx(0.01905 - static_overlap(20.0, coefficient), rel=1e-15)
    assert LATTICE.stiffness_n_m == pytest.approx(spring_stiffness(20.0, coefficient), rel=1e-15)
    assert LATTICE.mass_kg == pytest.approx(float(sphere_mass(0.01905)), rel=1e-15)


def test_gamma_k_and_m_by_hand():
    """Γ: 0, 0. K: every bond has 1 − cos = 3/2 and Σ e eᵀ = 3 I, so ω² = (9/2) k/m twice.
    M: two bond directions at phase π, one at 0: ω² = 4 (1 ± cos 60°) k/m = 2 and 6 k/m."""
    points = LATTICE.high_symmetry_points()
    np.testing.assert_allclose(frequencies(LATTICE, points["Γ"]), [0.0, 0.0], atol=1e-9 * SCALE)
    np.testing.assert_allclose(frequencies(LATTICE, points["K"]) / SCALE, [math.sqrt(4.5)] * 2, rtol=1e-12)
    np.testing.assert_allclose(frequencies(LATTICE, points["M"]) / SCALE, [math.sqrt(2), math.sqrt(6)], rtol=1e-12)
    np.testing.assert_allclose(
        dynamical_matrix(LATTICE, points["K"]), 4.5 * SCALE**2 * np.eye(2), rtol=1e-12, atol=1e-9 * SCALE**2
    )


@pytest.mark.parametrize("angle_deg", [0.0, 37.0, 90.0, 200.0, 300.0])
def test_the_bands_meet_in_a_cone_at_k(angle_deg):
    """ω = ω_K ± v_D |q − K| in every direction, v_D = (√6/8) a sqrt(k/m): the split over 2 |q − K|
    tends to v_D linearly in |q − K| (second order: measured against two step sizes)."""
    direction = np.array([math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))])
    k_point = LATTICE.high_symmetry_points()["K"]
    slopes = []
    for step in (1e-3, 2e-3):
        lower, upper = frequencies(LATTICE, k_point + step / LATTICE.spacing_m * direction)
        slopes.append((upper - lower) / 2 / (step / LATTICE.spacing_m))
    extrapolated = 2 * slopes[0] - slopes[1]  # Richardson: the error is linear in the step
    assert extrapolated == pytest.approx(cone_slope(LATTICE), rel=1e-5)


def test_long_waves_travel_at_the_lame_sound_speeds():
    """c_L = sqrt(9/8) a sqrt(k/m) (hexdem.model.precompression's) and c_T = sqrt(3/8) a sqrt(k/m),
    the same in every direction (the lattice's long-wave limit is isotropic)."""
    c_l, c_t = sound_speeds(LATTICE)
    coefficient = float(hertz_coefficient(0.01905))
    assert c_l == pytest.approx(
        longitudinal_sound_speed(20.0, coefficient, LATTICE.mass_kg, LATTICE.spacing_m), rel=1e-12
    )
    q = 1e-5 / LATTICE.spacing_m
    for angle in np.radians([0.0, 17.0, 45.0, 90.0]):
        low, high = frequencies(LATTICE, q * np.array([math.cos(angle), math.sin(angle)])) / q
        assert (low, high) == (pytest.approx(c_t, rel=1e-8), pytest.approx(c_l, rel=1e-8))


def test_the_band_path_runs_gamma_k_m_gamma():
    position, vectors, omega = band_path(LATTICE, 30)
    points = LATTICE.high_symmetry_points()
    assert len(position) == 91 and np.all(np.diff(position) > 0)
    np.testing.assert_allclose(
        vectors[[0, 30, 60, 90]], [points["Γ"], points["K"], points["M"], points["Γ"]], atol=1e-9
    )
    np.testing.assert_allclose(omega[30], [math.sqrt(4.5) * SCALE] * 2, rtol=1e-12)
    assert np.all(omega[:, 1] >= omega[:, 0])


def test_the_path_runs_along_the_zone_edge_from_k_to_m():
    """K and M are neighbours on the zone's edge: |K − M| = 2π/(3a), half an edge of the
    hexagonal zone whose corners lie 4π/(3a) from Γ, and M is at distance 2π/(√3 a) = the
    zone's inradius."""
    points = LATTICE.high_symmetry_points()
    a = LATTICE.spacing_m
    assert np.linalg.norm(points["K"] - points["M"]) == pytest.approx(2 * math.pi / (3 * a), rel=1e-12)
    assert np.linalg.norm(points["M"]) == pytest.approx(2 * math.pi / (math.sqrt(3) * a), rel=1e-12)


def test_an_uncompressed_packing_has_no_linear_lattice():
    with pytest.raises(HexdemError, match="precompression > 0"):
        Lattice2D.precompressed(0.0, 0.01905)
