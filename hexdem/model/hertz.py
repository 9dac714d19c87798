r"""Analytic Hertz two-body collision (Johnson 1987), the yardstick for contact times.

Two bodies with reduced mass μ approaching at relative speed v with a contact force
:math:`F = A δ^{3/2}` (:math:`A = k_n \sqrt{R_\text{eff}}`) stop approaching at the maximum
overlap

.. math::

    δ_\text{max} = \left(\frac{5 μ v^2}{4 A}\right)^{2/5}

and separate, undamped, after the contact time

.. math::

    τ = 2 \frac{δ_\text{max}}{v} \int_0^1 (1 − x^{5/2})^{−1/2}\, dx
      = \tfrac{4}{5} B(\tfrac{2}{5}, \tfrac{1}{2}) \frac{δ_\text{max}}{v} ≈ 2.9432\, \frac{δ_\text{max}}{v}.

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
