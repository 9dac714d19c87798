"""Analytic Hertz two-body collision (Johnson 1987), the yardstick for contact times.

Two bodies with reduced mass μ approaching at relative speed v with a contact force
F = A δ^{3/2} (A = k_n sqrt(R_eff)) stop approaching at the maximum overlap ::

    δ_max = (5 μ v² / (4 A))^{2/5}

and separate, undamped, after the contact time ::

    τ = 2 (δ_max / v) ∫₀¹ (1 − x^{5/2})^{−1/2} dx
      = (4/5) B(2/5, 1/2) δ_max / v ≈ 2.9432 δ_max / v.

A sphere against a flat wall is the case μ = M, R_eff = R.
"""

from __future__ import annotations

import math

import numpy as np

#: τ v / δ_max = (4/5) B(2/5, 1/2) ≈ 2.94327, with B(a, b) = Γ(a) Γ(b) / Γ(a + b).
CONTACT_TIME_FACTOR = 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)


def max_overlap(reduced_mass, hertz_coefficient, speed):
    """δ_max [m] of a head-on Hertz collision (SI, or any consistent units)."""
    return (5.0 * reduced_mass * np.asarray(speed) ** 2 / (4.0 * hertz_coefficient)) ** 0.4


def contact_time(reduced_mass, hertz_coefficient, speed):
    """Duration τ of an undamped head-on Hertz collision at relative ``speed``."""
    return CONTACT_TIME_FACTOR * max_overlap(reduced_mass, hertz_coefficient, speed) / np.asarray(speed)
