"""Dissipative Hertz contacts with a prescribed coefficient of restitution (Tsuji et al. 1992).

The paper's model is conservative (Sec. III); its experiments arrive later and weaker, which
it puts down to dissipation (Sec. VI-B). hexdem adds Tsuji's viscous damping to the Hertz law,
for an overlap δ and its rate δ̇ (positive while the bodies approach):

    F = A δ^{3/2} + η δ̇,   η = α sqrt(m_eff A) δ^{1/4},

with A = k_n sqrt(R_eff) and m_eff the reduced mass (the body's own mass against a wall).
The force is applied while δ > 0 and may turn slightly attractive at the very end of a
contact, as in LAMMPS's ``damping tsuji``. In the units m_eff = A = 1 and with the impact
speed v as velocity unit, x = δ/δ_v obeys x'' = −x^{3/2} − α x^{1/4} x' (δ_v = (m v²/A)^{2/5}):
both forces scale as v^{6/5}, so the restitution e = −x'(end)/x'(0) depends on α only, not on
the speed. :func:`damping_coefficient` inverts e(α) by integrating that equation.

LAMMPS's ``damping tsuji`` takes a coefficient c and applies α = P(c), Marshall's (2009)
polynomial fit. The fit is approximate: measured with the installed LAMMPS (22 Jul 2025),
c = 0.95 gives e = 0.965 and c = 0.8 gives e = 0.853, exactly the e(α) of the equation above
with α = P(c) (newer LAMMPS sources multiply by √2; hexdem's restitution tests on real LAMMPS
would catch that change). hexdem therefore hands LAMMPS the c whose α gives the requested e
(:func:`lammps_tsuji_coefficient`).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from hexdem.errors import HexdemError

# scipy's ODE solver and root finder are imported inside the functions that need them: only
# a damped run does, and importing them costs an undamped run half a second of start-up.

#: Marshall's polynomial P(c) = Σ p_k c^k by which LAMMPS's ``damping tsuji`` sets α = P(c).
TSUJI_POLYNOMIAL = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)


def restitution_of(alpha: float) -> float:
    """The coefficient of restitution of a head-on Tsuji-damped Hertz collision with damping α."""
    from scipy.integrate import solve_ivp

    def rhs(t, state):
        x, v = state
        x = max(x, 0.0)
        return [v, -x**1.5 - alpha * x**0.25 * v]

    def separated(t, state):
        return state[0]

    separated.terminal, separated.direction = True, -1
    solution = solve_ivp(rhs, (0.0, 100.0), [0.0, 1.0], events=separated, rtol=1e-11, atol=1e-13,
                         first_step=1e-6)
    if not solution.t_events[0].size:
        return 0.0  # the bodies stay together: all the approach energy is dissipated
    return float(-solution.y_events[0][0][1])


@cache
def damping_coefficient(restitution: float) -> float:
    """α of Tsuji's damping that gives the coefficient of ``restitution`` e ∈ (0, 1] (0 for e = 1)."""
    check_restitution("restitution", restitution)
    if restitution == 1.0:
        return 0.0
    from scipy.optimize import brentq

    return float(brentq(lambda alpha: restitution_of(alpha) - restitution, 0.0, 20.0, xtol=1e-13))


def lammps_tsuji_coefficient(alpha: float) -> float:
    """The coefficient c to give LAMMPS's ``damping tsuji`` so that it applies damping ``alpha``."""
    from scipy.optimize import brentq

    def applied(c: float) -> float:
        return float(np.polynomial.polynomial.polyval(c, TSUJI_POLYNOMIAL))

    if not applied(1.0) <= alpha <= applied(0.0):
        raise HexdemError(f"LAMMPS's damping tsuji cannot express the restitution {restitution_of(alpha):.4g}: "
                          f"use one in [{restitution_of(applied(0.0)):.3f}, {restitution_of(applied(1.0)):.4f}] or 1")
    return float(brentq(lambda c: applied(c) - alpha, 0.0, 1.0, xtol=1e-14))


def check_restitution(name: str, value) -> float:
    """``value`` if it is a coefficient of restitution in (0, 1], else a one-line HexdemError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 < value <= 1.0:
        raise HexdemError(f"{name} must be a coefficient of restitution in (0, 1], got {value!r}")
    return float(value)
