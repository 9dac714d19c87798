"""The energy budget of a frictional impact (a sphere on a wall), both engines.

With Mindlin's spring f = k ξ, k = k_t a = K sqrt(δ), the energy stored in it is U_t = ½ k ξ². The
tangential force takes power −f s from the bodies (s the contact points' slip velocity), and
dU_t/dt = f ξ' + ½ ξ² k'. So

    K_trans + K_rot + U_n + U_t + D − W = E₀,   D = ∫ f (s − ξ') dt ≥ 0,   W = ∫ ½ ξ² dk,

D the energy friction dissipates (ξ' ≠ s only on slip) and W the work of the spring's stiffness
changing with the contact radius: k_t ∝ a makes the displacement-based Mindlin spring not
conservative by itself, and the budget closes only with W. U_n = (2/5) A δ^{5/2} is Hertz's.
"""

import numpy as np
import pytest
from conftest import V0, D
from oblique import INERTIA, Contact, impact_settings, lammps_states, reference_states, sphere_on_wall

MU = 0.3


def budget(model, states):
    """(E₀, K + U_n + U_t, D, W) over time from every step's state (trapezoid sums for D and W; the
    histories ξ taken at the Coulomb cap, where the next step sets them)."""
    contact = Contact.of(model)
    mass, radius = model.masses_kg[0], D / 2
    depth = np.maximum(-states.positions[:, 0, 1], 0.0)  # the wall's surface is y = −D/2
    bound = MU * contact.k_n * depth / contact.k_t
    xi = np.clip(states.wall_histories[:, 0], -bound, bound)
    stiffness = contact.k_t * np.sqrt(contact.r_eff * depth)
    force = stiffness * xi
    slip = -states.velocities[:, 0, 0] - radius * states.spins[:, 0]  # t = ẑ × n = −x for the normal +y
    dt = np.diff(states.times)
    dissipated = np.cumsum(
        (force[1:] * slip[1:] + force[:-1] * slip[:-1]) / 2 * dt - (force[1:] + force[:-1]) / 2 * np.diff(xi)
    )
    stiffening = np.cumsum((xi[1:] ** 2 + xi[:-1] ** 2) / 4 * np.diff(stiffness))
    kinetic = (
        0.5 * mass * (states.velocities[:, 0] ** 2).sum(axis=1)
        + 0.5 * INERTIA * mass * radius**2 * states.spins[:, 0] ** 2
    )
    stored = 0.4 * contact.k_n * np.sqrt(contact.r_eff) * depth**2.5 + 0.5 * stiffness * xi**2
    return kinetic[0], kinetic + stored, np.concatenate([[0.0], dissipated]), np.concatenate([[0.0], stiffening])


@pytest.mark.parametrize("incidence_deg", [10.0, 25.0, 45.0])
def test_reference_energy_budget_closes_with_friction_and_stiffening_work(incidence_deg):
    """Stick then slip (10°: mostly stick; 45°: mostly slip): the budget's residual shrinks as dt²
    (second-order sums), far below both D and W, which it needs."""
    model = sphere_on_wall(incidence_deg, MU)
    residuals = []
    for steps in (200, 400):
        e0, mechanical, dissipated, stiffening = budget(model, reference_states(model, impact_settings(model, steps)))
        residual = np.abs(mechanical + dissipated - stiffening - e0).max() / e0
        residuals.append(residual)
        increments = np.diff(dissipated) / e0
        assert increments.min() > -residual  # friction only takes energy, to the sums' accuracy
        assert dissipated[-1] / e0 > 30 * residual and abs(stiffening[-1]) / e0 > 30 * residual
    assert residuals[1] < residuals[0] / 3  # second order


def test_lammps_loses_the_energy_the_reference_budget_says_friction_takes(tmp_path):
    """After the impact U_t = U_n = 0, so LAMMPS's final K_trans + K_rot must be E₀ − D + W of the
    reference engine's budget, within LAMMPS's change from τ/400 to τ/800 and the budget's residual."""
    model = sphere_on_wall(25.0, MU)
    e0, mechanical, dissipated, stiffening = budget(model, reference_states(model, impact_settings(model, 400)))
    residual = np.abs(mechanical + dissipated - stiffening - e0).max() / e0
    finals = []
    for steps in (400, 800):
        settings = impact_settings(model, steps)
        states = lammps_states(model, settings, tmp_path / str(steps), every=settings.n_steps)
        mass = model.masses_kg[0]
        finals.append(
            0.5 * mass * (states.velocities[-1, 0] ** 2).sum()
            + 0.5 * INERTIA * mass * (D / 2) ** 2 * states.spins[-1, 0] ** 2
        )
    expected = e0 - dissipated[-1] + stiffening[-1]
    assert finals[1] == pytest.approx(expected, rel=2 * abs(finals[0] - finals[1]) / e0 + residual)
    assert e0 - finals[1] > 0.01 * e0  # friction took a visible share
    assert 0.5 * model.masses_kg[0] * V0**2 == pytest.approx(e0, rel=1e-12)
