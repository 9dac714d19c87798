r"""Conical diffraction at the Dirac point: how fast a Gaussian packet built at K opens into a ring.

Near K both bands of :mod:`hexdem.theory.phonons` meet in a cone. A packet of the waves near
(K, +ω_K), :math:`u = \operatorname{Re}[ψ(r, t)\, e^{i(K \cdot r − ω_K t)}]`, has an envelope ψ (a complex 2-vector of
polarizations) that obeys, to first order in q = k − K, a Dirac equation

    i ∂ψ/∂t = H(q) ψ,   H(q) = (D(K + q) − D(K − q)) / (4 ω_K) = v_D |q| M(θ),

where θ is q's direction and M(θ) a real symmetric traceless matrix with eigenvalues ±1
(:func:`dirac_matrix`). So ψ(q, t) = [cos(v_D q t) − i sin(v_D q t) M(θ)] ψ(q, 0): every component
splits between the upper and the lower cone, which carry it away from the centre at v_D, and a
packet of width σ becomes a ring (Berry's conical diffraction).

**The ring's radius.** With the energy density |ψ(r)|² as weight, the packet's mean square
distance from its centre is ⟨r²⟩ = ∫|∇_q ψ|² / ∫|ψ|² (Parseval). The ring radius
R(t) = sqrt(⟨r²⟩(t) − ⟨r²⟩(0)) starts as √2 v_D t (both the radial and the angular part of
∇_q ψ gain v_D t |ψ|) and grows as v_D t only asymptotically: the cone's apex, where M turns
with θ, leaves a diffuse interior whose share of ⟨r²⟩ grows like log t. :func:`cone_ring_radius`
therefore integrates the whole R(t) of the cone for ψ(q, 0) = exp(−σ² q²/2) χ, in polar
coordinates, |∇ψ|² = |∂_q ψ|² + |∂_θ ψ|²/q². By dimensional analysis R = σ F(v t / σ) with F
set by χ alone; a measured R(t) fitted with v as the only free parameter gives the cone's slope.

**The polarization.** M(θ) mixes both real polarizations, so a packet of one of them drifts
(its ⟨ψ|M|ψ⟩ is not zero); the circular χ = (1, i)/√2 has ⟨M(θ)⟩ = 0 in every direction and
stays centred (:data:`CIRCULAR`).
"""

from __future__ import annotations

import math

import numpy as np

from hexdem.theory.phonons import Lattice2D, cone_slope, dynamical_matrix

#: The circular polarization, whose packet at K does not drift.
CIRCULAR = np.array([1.0, 1.0j]) / math.sqrt(2.0)


def dirac_matrix(lattice: Lattice2D, angle_rad: float) -> np.ndarray:
    """M(θ) (2, 2) of the module docstring: H(q) / (v_D |q|) along ``angle_rad``, from the
    dynamical matrix's part odd in q about K, taken at |q| = 1e-6 / a (first order)."""
    k_point = lattice.high_symmetry_points()["K"]
    step = 1e-6 / lattice.spacing_m * np.array([math.cos(angle_rad), math.sin(angle_rad)])
    omega_k = lattice.dirac_frequency()
    odd = dynamical_matrix(lattice, k_point + step) - dynamical_matrix(lattice, k_point - step)
    return odd / (4 * omega_k * cone_slope(lattice) * np.linalg.norm(step))


def cone_ring_radius(
    lattice: Lattice2D,
    width_m: float,
    times_s,
    polarization=CIRCULAR,
    speed_m_s=None,
    radial_points: int = 1500,
    angles: int = 96,
) -> np.ndarray:
    """R(t) [m] (see the module docstring) of a packet of envelope width ``width_m`` (σ) and
    ``polarization`` χ at ``times_s``, the cone's slope ``speed_m_s`` (None: v_D of ``lattice``),
    integrated on ``radial_points`` × ``angles`` points out to |q| = 6/σ."""
    speed = cone_slope(lattice) if speed_m_s is None else speed_m_s
    chi = np.asarray(polarization, complex) / np.linalg.norm(polarization)
    theta = 2 * np.pi * np.arange(angles) / angles
    dtheta = 2 * np.pi / angles
    q = (np.arange(radial_points) + 0.5) * 6.0 / width_m / radial_points
    dq = q[1] - q[0]
    m_chi = np.array([dirac_matrix(lattice, angle) @ chi for angle in theta])  # (A, 2)
    # M is linear in (cos θ, sin θ), so dM/dθ = M(θ + π/2) exactly
    dm_chi = np.array([dirac_matrix(lattice, angle + np.pi / 2) @ chi for angle in theta])
    g = np.exp(-((width_m * q) ** 2) / 2)
    dg = -(width_m**2) * q * g
    weight = q[:, None] * dq * dtheta
    norm = np.sum(g**2 * q) * dq * 2 * np.pi
    second_moment = []
    for t in np.atleast_1d(np.asarray(times_s, float)):
        c, s = np.cos(speed * q * t)[:, None, None], np.sin(speed * q * t)[:, None, None]
        along = (-speed * t * s * chi - 1j * speed * t * c * m_chi) * g[:, None, None] + (
            c * chi - 1j * s * m_chi
        ) * dg[:, None, None]
        around = -1j * s * dm_chi * (g / q)[:, None, None]
        density = np.sum(np.abs(along) ** 2 + np.abs(around) ** 2, axis=2)
        second_moment.append(np.sum(density * weight) / norm)
    return np.sqrt(np.maximum(np.array(second_moment) - width_m**2, 0.0))
