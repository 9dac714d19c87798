r"""Ternary collision approximation (TCA) of Sec. IV, and residence times in the full lattice.

The TCA lives in the paper's nondimensional units A = d = M = 1 (eq. scaling).

**Three-bead system.** Bead 0 is struck along a line of touching beads; bead 1 lies ahead
of it on that line, beads a and b beside it at ±θ (θ = π/3 in the hexagonal packing). With
displacements x₀, x₁ along the line and x_a = x_b along the a and b bonds,

.. math::

    ẍ_0 = −[x_0 − x_1]_+^{3/2} − 2 \cos θ\, [\cos θ\, x_0 − x_a]_+^{3/2}, \quad
    ẍ_1 = [x_0 − x_1]_+^{3/2}, \quad ẍ_a = [\cos θ\, x_0 − x_a]_+^{3/2}.

Its energy :math:`\tfrac{1}{2}ẋ_0^2 + \tfrac{1}{2}ẋ_1^2 + ẋ_a^2 + \tfrac{2}{5}[z]_+^{5/2} + \tfrac{4}{5}[y]_+^{5/2}`
(both side beads) and its momentum ẋ₀ + ẋ₁ + 2 cos θ ẋ_a along the line are conserved.

**Reduced form**, eq. (5). With z = x₀ − x₁ and y = cos θ x₀ − x_a,
:math:`(\ddot z, \ddot y) = −K (z_+^{3/2}, y_+^{3/2})`, K = [[2, 2 cos θ], [cos θ, 2 cos²θ + 1]]
= [[2, 1], [1/2, 3/2]] at θ = π/3. K = N diag(1, 2) with N = J M⁻¹ Jᵀ the inverse mass matrix of
the strains, so :math:`\tfrac{1}{2} \dot q^T N^{-1} \dot q + \tfrac{2}{5} z_+^{5/2} + \tfrac{4}{5} y_+^{5/2}`
is conserved by eq. (5).

**ω** solves the compatibility condition :math:`2 + ω^{3/2} = (\tfrac{1}{2} + \tfrac{3}{2} ω^{3/2})/ω` of the ansatz
y = ω z (the initial conditions would need ω = cos θ = 1/2). With s = √ω it reads
2s⁵ − 3s³ + 4s² − 1 = (s² + s − 1)(2s³ − 2s² + s + 1) = 0, so ω = ((√5 − 1)/2)² = (3 − √5)/2.

**c**, eq. (8): the common velocity of beads 0 and 1 at the moment they become
equal (ż = 0), divided by the BCA's V₀/2. It does not depend on V₀: the Hertz system is
invariant under :math:`x → λx,\ t → λ^{−1/4} t,\ v → λ^{5/4} v`.

**Residence times.** The TCA's T_n is the time from z = 0, ż = V_n, y = 0, ẏ = V_n cos θ to
ż = 0, with V_n = V₀ cⁿ; the pulse speed is c_n = 1/T_n. Under the ansatz
:math:`\ddot z = −k z^{3/2}`, :math:`k = 2 + ω^{3/2}`, solved by eq. (6):

.. math::

    t(z) = {}_2F_1\left(\tfrac{2}{5}, \tfrac{1}{2}; \tfrac{7}{5}; \frac{2 k z^{5/2}}{5E}\right)
    \frac{z}{\sqrt{2E}}, \qquad E = V^2/2.

The paper prints :math:`\sqrt{k}` in the argument; k is what energy conservation
:math:`\tfrac{1}{2}\dot z^2 + \tfrac{2k}{5} z^{5/2} = E` gives, and what :func:`hypergeometric_time` uses (the tests
check
it against direct integration).

**Full lattice.** T_n as the paper defines it: t = 0 when the velocities of beads n − 1 and
n become equal, T_n when those of n and n + 1 do (:func:`lattice_pulses`). Velocities are
compared as speeds |v|, the quantity Sec. V fits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.special import hyp2f1

from hexdem.analysis.peaks import rising_crossing
from hexdem.common.checks import is_number
from hexdem.errors import HexdemError

#: Angle between the struck line and the side beads in the hexagonal packing.
THETA = np.pi / 3
#: Fraction of V₀ that beads 0 and 1 share when their velocities meet in the 1D BCA.
BCA_EQUAL_VELOCITY_FRACTION = 0.5
#: Integration tolerances of the TCA's ODEs (relative, absolute).
RTOL, ATOL = 1e-11, 1e-14


def _pos32(u):
    return np.maximum(u, 0.0) ** 1.5


def _pos52(u):
    return np.maximum(u, 0.0) ** 2.5


def three_bead_rhs(t, state, theta: float = THETA):
    """Right-hand side of the three-bead TCA; ``state`` = (x₀, x₁, x_a, ẋ₀, ẋ₁, ẋ_a)."""
    x0, x1, xa, u0, u1, ua = state
    f_line, f_side = _pos32(x0 - x1), _pos32(np.cos(theta) * x0 - xa)
    return np.array([u0, u1, ua, -f_line - 2 * np.cos(theta) * f_side, f_line, f_side])


def three_bead_energy(state, theta: float = THETA) -> float:
    """Conserved energy of the three-bead TCA, both side beads counted."""
    x0, x1, xa, u0, u1, ua = np.asarray(state, float)
    z, y = x0 - x1, np.cos(theta) * x0 - xa
    return float(0.5 * u0**2 + 0.5 * u1**2 + ua**2 + 0.4 * _pos52(z) + 0.8 * _pos52(y))


def three_bead_momentum(state, theta: float = THETA) -> float:
    """Conserved momentum along the struck line: ẋ₀ + ẋ₁ + 2 cos θ ẋ_a."""
    u0, u1, ua = np.asarray(state, float)[3:6]
    return float(u0 + u1 + 2 * np.cos(theta) * ua)


def strain_matrix(theta: float = THETA) -> np.ndarray:
    r"""K of eq. (5): :math:`(\ddot z, \ddot y) = −K (z_+^{3/2}, y_+^{3/2})`; [[2, 1], [1/2, 3/2]]
    at π/3."""
    c = np.cos(theta)
    return np.array([[2.0, 2 * c], [c, 2 * c * c + 1.0]])


def strain_rhs(t, state, theta: float = THETA):
    """Right-hand side of eq. (5); ``state`` = (z, y, ż, ẏ)."""
    z, y, zd, yd = state
    acc = -strain_matrix(theta) @ np.array([_pos32(z), _pos32(y)])
    return np.array([zd, yd, acc[0], acc[1]])


def strain_energy(state, theta: float = THETA) -> float:
    r"""Conserved quantity of eq. (5):
    :math:`\tfrac{1}{2} \dot q^T N^{-1} \dot q + \tfrac{2}{5} z_+^{5/2} + \tfrac{4}{5} y_+^{5/2}`."""
    z, y, zd, yd = np.asarray(state, float)
    inverse_mass = strain_matrix(theta) @ np.diag([1.0, 0.5])
    rates = np.array([zd, yd])
    return float(0.5 * rates @ np.linalg.solve(inverse_mass, rates) + 0.4 * _pos52(z) + 0.8 * _pos52(y))


def compatibility_residual(omega):
    r""":math:`2 + ω^{3/2} − (\tfrac{1}{2} + \tfrac{3}{2} ω^{3/2})/ω`: zero where y = ω z solves
    eq. (5)."""
    omega = np.asarray(omega, float)
    return 2.0 + omega**1.5 - (0.5 + 1.5 * omega**1.5) / omega


def solve_omega() -> float:
    """The sole real root ω of the compatibility condition (the residual increases
    monotonically from −∞ at ω → 0⁺; :math:`ω^{3/2}` is not real for ω < 0)."""
    return float(brentq(compatibility_residual, 1e-6, 1.0, xtol=1e-15, rtol=4 * np.finfo(float).eps))


def _until_rate_vanishes(rhs, state0, rate, theta: float, v: float):
    """Integrate ``rhs`` from ``state0`` until ``rate(state)`` falls through zero:
    (time, state, dense solution)."""

    def stops(t, s, theta):
        return rate(s)

    stops.terminal, stops.direction = True, -1
    horizon = 50.0 * v**-0.2  # many Hertz contact times at speed v (A = M = 1)
    sol = solve_ivp(
        rhs,
        (0.0, horizon),
        state0,
        args=(theta,),
        method="DOP853",
        rtol=RTOL,
        atol=ATOL,
        events=stops,
        dense_output=True,
    )
    if not sol.t_events[0].size:
        raise HexdemError("the TCA never reached equal velocities of beads 0 and 1")
    return float(sol.t_events[0][0]), sol.y_events[0][0], sol


def _positive(v, what: str = "V") -> float:
    if not (is_number(v) and v > 0):
        raise HexdemError(f"the TCA needs a velocity > 0, got {what} = {v}")
    return float(v)


@dataclass(frozen=True)
class EqualVelocity:
    """The moment t* at which beads 0 and 1 of the three-bead TCA move equally fast.

    ``time`` t*; ``state`` (x₀, x₁, x_a, ẋ₀, ẋ₁, ẋ_a) at t*; ``v0`` the initial velocity of
    bead 0; ``solution`` the dense ``solve_ivp`` solution on [0, t*] (all nondimensional).
    """

    time: float
    state: np.ndarray
    v0: float
    solution: object

    @property
    def velocity(self) -> float:
        """ẋ₀ = ẋ₁ at t*."""
        return float(self.state[3])

    @property
    def decay_factor(self) -> float:
        """c = ẋ₀(t*) / (V₀/2): the velocity reached relative to the BCA's (eq. (8))."""
        return self.velocity / (BCA_EQUAL_VELOCITY_FRACTION * self.v0)


def equal_velocity(v0: float = 1.0, theta: float = THETA) -> EqualVelocity:
    """Integrate the three-bead TCA from bead 0 moving at ``v0`` until ẋ₀ = ẋ₁."""
    v0 = _positive(v0, "V0")
    state0 = np.array([0.0, 0.0, 0.0, v0, 0.0, 0.0])
    t_star, state, sol = _until_rate_vanishes(three_bead_rhs, state0, lambda s: s[3] - s[4], theta, v0)
    return EqualVelocity(t_star, state, v0, sol)


def decay_factor(theta: float = THETA) -> float:
    """The TCA's c of eq. (8), the same for every V₀."""
    return equal_velocity(1.0, theta).decay_factor


def residence_time(v: float, theta: float = THETA) -> float:
    """T(V): eq. (5) from z = 0, ż = V, y = 0, ẏ = V cos θ until ż = 0."""
    v = _positive(v)
    state0 = np.array([0.0, 0.0, v, v * np.cos(theta)])
    return _until_rate_vanishes(strain_rhs, state0, lambda s: s[2], theta, v)[0]


def hypergeometric_time(z, v: float, omega: float):
    r"""Eq. (6): when z(t) of :math:`\ddot z = −(2 + ω^{3/2}) z^{3/2}`, z(0) = 0, ż(0) = v reaches z,
    for 0 ≤ z ≤ the maximum compression."""
    energy = 0.5 * _positive(v) ** 2
    k = 2.0 + omega**1.5
    z = np.asarray(z, float)
    argument = np.minimum(2.0 * k * z**2.5 / (5.0 * energy), 1.0)
    return hyp2f1(0.4, 0.5, 1.4, argument) * z / np.sqrt(2.0 * energy)


def hypergeometric_residence_time(v: float, omega: float) -> float:
    """Closed-form T(V): eq. (6) at the maximum compression :math:`(5E/(2k))^{2/5}`, where ż = 0."""
    energy = 0.5 * _positive(v) ** 2
    z_max = (5.0 * energy / (2.0 * (2.0 + omega**1.5))) ** 0.4
    return float(hypergeometric_time(z_max, v, omega))


@dataclass(frozen=True)
class PulsePrediction:
    r"""TCA residence times along the 30° line (nondimensional).

    ``n`` bead numbers; ``velocity`` :math:`V_n = V_\text{first}\, c^{n − n_\text{first}}`;
    ``residence_time`` T_n from eq. (5); ``residence_time_hyperg`` T_n from eq. (6).
    """

    n: np.ndarray
    velocity: np.ndarray
    residence_time: np.ndarray
    residence_time_hyperg: np.ndarray

    @property
    def pulse_speed(self) -> np.ndarray:
        """c_n = 1/T_n [bead diameters per time unit]."""
        return 1.0 / self.residence_time

    @property
    def pulse_speed_hyperg(self) -> np.ndarray:
        return 1.0 / self.residence_time_hyperg

    def arrival_times(self, t_first: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Arrival of the pulse at beads n + 1 for each n: ``t_first`` (its arrival at the
        first bead) plus the summed residence times of eq. (5) and of eq. (6)."""
        return t_first + np.cumsum(self.residence_time), t_first + np.cumsum(self.residence_time_hyperg)


def predict_pulses(v_first: float, n_first: int, n_last: int, theta: float = THETA) -> PulsePrediction:
    r"""Residence times of beads n_first … n_last for
    :math:`V_n = v_\text{first}\, c^{n − n_\text{first}}` (eq. (8), started at bead n_first).

    30° strike: v_first = V₀ at n_first = 0. 0° strike observed at 30°: v_first = V₀/2 at
    n_first = 1 (Sec. IV, last paragraph).
    """
    if n_last < n_first:
        raise HexdemError(f"need n_last >= n_first, got {n_first}..{n_last}")
    c, omega = decay_factor(theta), solve_omega()
    n = np.arange(n_first, n_last + 1)
    velocity = v_first * c ** (n - n_first)
    return PulsePrediction(
        n,
        velocity,
        np.array([residence_time(v, theta) for v in velocity]),
        np.array([hypergeometric_residence_time(v, omega) for v in velocity]),
    )


@dataclass(frozen=True)
class LatticePulses:
    """Residence times measured along one line of a simulated lattice (run units).

    ``crossing_time[n]``: when |v| of bead n falls to |v| of bead n + 1 (first time after
    bead n's arrival); ``residence_time[n]`` T_n = crossing_time[n] − crossing_time[n − 1],
    with crossing_time[−1] = 0, the impact.
    """

    n: np.ndarray
    crossing_time: np.ndarray
    residence_time: np.ndarray

    @property
    def pulse_speed(self) -> np.ndarray:
        """c_n = 1/T_n."""
        return 1.0 / self.residence_time


def crossing_times(times, speeds, arrival) -> np.ndarray:
    """For neighbours n, n + 1 of a line: the first time after ``arrival[n]`` at which
    ``speeds[:, n]`` falls to ``speeds[:, n + 1]`` (spline-refined as in :mod:`hexdem.analysis.peaks`).

    ``times`` (F,); ``speeds`` (F, L) along the line; ``arrival`` (L,). NaN where bead n has
    no arrival or the two speeds never meet within the record.
    """
    times, speeds = np.asarray(times, float), np.asarray(speeds, float)
    out = np.full(speeds.shape[1] - 1, np.nan)
    for n in range(len(out)):
        if np.isfinite(arrival[n]):
            start = int(np.searchsorted(times, arrival[n]))
            out[n] = rising_crossing(times[start:], speeds[start:, n + 1] - speeds[start:, n], 0.0)
    return out


def lattice_pulses(analysis, line: str) -> LatticePulses:
    """Crossing and residence times along ``line`` of a finished
    :class:`~hexdem.analysis.impact.ImpactAnalysis` that traced ``line``, in the run's units."""
    times, speeds = analysis.line_trace(line)
    crossing = crossing_times(times, speeds, analysis.results.arrival_time[analysis.results.lines[line]])
    return LatticePulses(np.arange(len(crossing)), crossing, np.diff(np.concatenate([[0.0], crossing])))


def _impact_speed_m_s(analysis) -> float:
    """The speed of the run's impact [m/s]: the TCA follows the pulse of a single impact, which
    other fronts crossing the line would distort (a run of several is refused)."""
    impacts = analysis.model.impacts
    if len(impacts) != 1:
        raise HexdemError(f"the TCA comparison follows the pulse of a single impact; this run has {len(impacts)}")
    return impacts[0].speed_m_s


def _nondimensional_units(analysis):
    from hexdem.model.units import nondimensional

    return nondimensional(analysis.model.packing.diameter_m, analysis.model.bead)


def pulse_speed_table(analysis, line: str = "+30") -> dict:
    """Fig. 5a: c_n = 1/T_n along ``line`` of a 30°-strike run against the TCA started with the
    run's V₀ at n = 0. Arrays ``n``, ``lattice``, ``tca``, ``hyperg`` (nondimensional), NaN-free."""
    v0_m_s = _impact_speed_m_s(analysis)
    units = _nondimensional_units(analysis)
    measured = lattice_pulses(analysis, line)
    keep = np.isfinite(measured.residence_time)
    n = measured.n[keep]
    v0 = v0_m_s / units.velocity_m_s
    prediction = predict_pulses(v0, 0, int(n.max()))
    speed = measured.pulse_speed[keep] * units.time_s / analysis.settings.units.time_s
    return {"n": n, "lattice": speed, "tca": prediction.pulse_speed[n], "hyperg": prediction.pulse_speed_hyperg[n]}


def arrival_time_table(analysis, line: str = "+30") -> dict:
    """Fig. 5b: arrival time of the pulse at beads n ≥ 1 of ``line`` after a 0° strike, in the
    run's time unit. The lattice's arrival at n is when beads n − 1 and n move equally fast;
    the TCA's is the lattice's arrival at bead 1 (the anchor, as the paper anchors the
    experiment at its first sensor) plus the TCA residence times from V₁ = V₀/2 on."""
    v0_m_s = _impact_speed_m_s(analysis)
    units = _nondimensional_units(analysis)
    scale = analysis.settings.units.time_s / units.time_s
    lattice = lattice_pulses(analysis, line).crossing_time
    lattice = lattice[: np.flatnonzero(np.isfinite(lattice))[-1] + 1]
    v1 = 0.5 * v0_m_s / units.velocity_m_s
    prediction = predict_pulses(v1, 1, len(lattice) - 1)
    tca, hyperg = prediction.arrival_times(t_first=lattice[0] * scale)
    return {
        "n": np.arange(1, len(lattice) + 1),
        "lattice": lattice,
        "tca": np.concatenate([[lattice[0]], tca / scale]),
        "hyperg": np.concatenate([[lattice[0]], hyperg / scale]),
    }


def summary() -> dict:
    """ω, c and the TCA's timing at V₀ = 1 (T scales as :math:`V_0^{-1/5}`), nondimensional (``hexdem tca``)."""
    event = equal_velocity(1.0)
    omega = solve_omega()
    return {
        "omega": omega,
        "c": event.decay_factor,
        "compatibility_residual": float(compatibility_residual(omega)),
        "equal_velocity_fraction": event.velocity,
        "bca_equal_velocity_fraction": BCA_EQUAL_VELOCITY_FRACTION,
        "residence_time_at_v0_1": event.time,
        "residence_time_hyperg_at_v0_1": hypergeometric_residence_time(1.0, omega),
        "units": "nondimensional, A = d = M = 1",
    }
