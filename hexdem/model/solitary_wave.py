r"""Nesterenko's solitary wave of a chain of Hertzian spheres: the pulse that travels unchanged,
against which the paper (Sec. I) sets the hexagonal lattice's decaying one.

For equal spheres of diameter d, mass m = πρd³/6 and Hertz coefficient
:math:`A = E \sqrt{d} / (3(1 − ν^2))` (:math:`F = A δ^{3/2}`), the strain ξ = −∂u/∂x of a long
wave obeys (Nesterenko, *Dynamics of Heterogeneous Materials*, 2001, Sec. 1.2)

.. math::

    ξ_{tt} = c^2 \frac{∂^2}{∂x^2} \left[ ξ^{3/2} + \frac{d^2}{10}\, ξ^{1/4} \frac{∂^2}{∂x^2} ξ^{5/4} \right],
    \qquad c^2 = \frac{A d^{5/2}}{m} = \frac{2E}{πρ(1 − ν^2)},

whose travelling solution of speed V is

.. math::

    ξ(x − Vt) = \left(\frac{5V^2}{4c^2}\right)^2 \cos^4\!\left(\frac{\sqrt{10}\, (x − Vt)}{5d}\right),
    \qquad |x − Vt| ≤ \frac{5πd}{2\sqrt{10}} ≈ 2.48\, d.

A bead's velocity in that wave is v = V ξ, so its largest, V_m = V (5V²/(4c²))², gives
V⁵ = (16/25) c⁴ V_m: the speed law :func:`solitary_speed_m_s`. The pulse spans 5π/√10 ≈ 4.97 d
(:data:`SUPPORT_WIDTH_D`), and since v ∝ cos⁴, its speed profile is half its peak across
:data:`HALF_MAXIMUM_WIDTH_D` ≈ 1.81 d. The discrete chain runs slightly slower than this
continuum law, which drops the higher powers of d ∂/∂x of the chain's finite differences.
"""

from __future__ import annotations

import math

from hexdem.model.materials import Material

#: Width of the continuum solitary wave's support, 5π/√10 diameters.
SUPPORT_WIDTH_D = 5 * math.pi / math.sqrt(10)
#: Width at half maximum of its velocity (and strain) profile, cos⁴ = 1/2:
#: :math:`2 \arccos(2^{−1/4}) \cdot 5/\sqrt{10}` diameters.
HALF_MAXIMUM_WIDTH_D = 2 * math.acos(2**-0.25) * 5 / math.sqrt(10)


def chain_speed_scale_m_s(material: Material) -> float:
    r"""Nesterenko's :math:`c = \sqrt{2E / (πρ(1 − ν^2))}` [m/s] of a chain of equal spheres of ``material``
    (independent of their diameter)."""
    return math.sqrt(
        2 * material.youngs_modulus_pa / (math.pi * material.density_kg_m3 * (1 - material.poisson_ratio**2))
    )


def solitary_speed_m_s(c_m_s: float, peak_velocity_m_s: float) -> float:
    """:math:`V_s = (16/25)^{1/5} c^{4/5} V_m^{1/5}` [m/s]: the speed of the solitary wave whose beads
    reach ``peak_velocity_m_s`` (see the module docstring)."""
    return (16 / 25) ** 0.2 * c_m_s**0.8 * peak_velocity_m_s**0.2


def strain_amplitude(c_m_s: float, speed_m_s: float) -> float:
    """ξ_m = (5V²/(4c²))²: the largest strain (overlap over diameter) of the wave of speed V."""
    return (5 * speed_m_s**2 / (4 * c_m_s**2)) ** 2
