"""Friction on a damped contact (Tsuji's damping, restitution 0.8 against the wall): both engines keep
the normal damping and cap the tangential force at μ |F_n| with F_n the damped normal force (LAMMPS's
``fncrit``), so they must agree, within their convergence in the time step, on the rebound and spin.

LAMMPS converges slowly here (its damping force takes half-step velocities: at 10° its ω r moves by
2.0e-3 and 1.0e-3 of itself from τ/400 to τ/800 to τ/1600, first order), the reference engine fast
(3e-5 and 7e-6); the normal force is clipped at zero in both (:mod:`hexdem.model.dissipation`). The
bound is the sum of each engine's change over its last halving, doubled (``oblique.convergence_bound``)."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import V0, D
from oblique import convergence_bound, impact_settings, lammps_states, reference_states, sphere_on_wall

MU = 0.3


@pytest.mark.parametrize("incidence_deg", [10.0, 45.0])
def test_engines_agree_on_a_damped_frictional_impact(tmp_path, incidence_deg):
    model = replace(sphere_on_wall(incidence_deg, MU), wall_restitution=0.8)
    scale = MU * 1.8 * V0 * np.cos(np.radians(incidence_deg))  # μ(1 + e) v_n
    results = {}
    for steps in (800, 1600):
        settings = impact_settings(model, steps)
        for name, states in (
            ("lammps", lammps_states(model, settings, tmp_path / str(steps), every=settings.n_steps)),
            ("reference", reference_states(model, settings, every=settings.n_steps)),
        ):
            results[name, steps] = np.array([*states.velocities[-1, 0], states.spins[-1, 0] * D / 2])
    assert results["lammps", 1600][1] == pytest.approx(0.8 * V0 * np.cos(np.radians(incidence_deg)), rel=1e-3)
    for q in (0, 2):  # tangential velocity, spin
        bound = sum(
            convergence_bound(results[name, 800][q], results[name, 1600][q], scale, 800)
            for name in ("lammps", "reference")
        )
        assert abs(results["lammps", 1600][q] - results["reference", 1600][q]) <= bound, q
