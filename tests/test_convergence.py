"""The default time step is chosen by accuracy: both engines converge at their integrator's order
(velocity Verlet 2, RK4 4), and at the default 140 steps per contact the peaks are within 1e-4 and
the arrival times within 0.05 µs of the Richardson-extrapolated answer (the issue's target), on
the paper's experiment and over the sweep's range of V0. The sampling interval stays 1/20 of the
contact time whatever the step, and its own error leaves the step's inside the target."""

import math

import numpy as np
import pytest
from conftest import contact_of, settings_of

from hexdem.errors import HexdemError
from hexdem.experiments.compare import ARRIVAL_ERROR_N2, ARRIVAL_GROWTH_N2, expected_error
from hexdem.experiments.convergence import (
    CHAIN,
    Convergence,
    arrival_growth,
    richardson,
    sampling_error,
    steps_config,
    study_time_step,
)
from hexdem.model.config import STEPS_PER_CONTACT, RunConfig
from hexdem.model.run_settings import SAMPLES_PER_CONTACT

PEAK_TARGET, ARRIVAL_TARGET_S = 1e-4, 0.05e-6


def test_richardson_recovers_the_limit_of_a_power_law_error():
    exact, c = 2.0, 0.3
    value = lambda h, p: exact + c * h**p
    for p in (2, 4):
        assert richardson(value(0.1, p), value(0.2, p), 2.0, p) == pytest.approx(exact, rel=1e-12)
        assert richardson(value(0.1, p), value(0.3, p), 3.0, p) == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("steps, dt_steps, every", [(None, 140, 7), (700, 700, 35), (110, 120, 6), (30, 40, 2)])
def test_the_step_follows_steps_per_contact_and_the_sampling_stays_fixed_in_time(steps, dt_steps, every):
    config = RunConfig() if steps is None else RunConfig(steps_per_contact=steps)
    settings, tau = settings_of(config), contact_of(config)
    assert settings.dt_s == pytest.approx(tau / dt_steps, rel=1e-12) and settings.dump_every == every
    assert settings.dt_s * settings.dump_every == pytest.approx(tau / SAMPLES_PER_CONTACT, rel=1e-12)
    assert settings.duration_s == pytest.approx(settings_of(RunConfig(steps_per_contact=700)).duration_s, rel=1e-3)


def test_too_few_steps_per_contact_is_refused():
    with pytest.raises(HexdemError, match="steps_per_contact must be at least 20"):
        RunConfig(steps_per_contact=10)
    with pytest.raises(HexdemError, match=f"multiples of {SAMPLES_PER_CONTACT}"):
        steps_config(RunConfig(), 110)


@pytest.mark.parametrize(
    "config",
    [RunConfig(), RunConfig(edge_beads=8, wall_material="none", units="nondimensional", v0=0.3)],
    ids=["experiment", "V0=0.30"],
)
def test_lammps_converges_at_second_order_and_its_default_meets_the_target(config, tmp_path):
    study = study_time_step(config, (80, STEPS_PER_CONTACT, 280, 560), tmp_path)
    assert study.n_beads >= 20
    assert all(1.8 < order < 2.2 for order in study.observed_orders), study.observed_orders
    default = study.at(STEPS_PER_CONTACT)
    assert default.peak_error < PEAK_TARGET
    assert default.arrival_error_contacts < ARRIVAL_TARGET_S / contact_of(RunConfig())  # the same in τ
    assert default.energy_drift < PEAK_TARGET
    for run in study.runs:  # the accuracy from which hexdem compare's default tolerances follow, bead by bead
        peak, arrival, growth = expected_error(run.steps_per_contact)
        assert run.peak_error <= peak, run
        assert np.all(np.abs(run.arrival_errors) <= arrival + growth * study.arrivals), run


def test_lammps_arrival_errors_grow_with_the_time_the_pulse_has_travelled(tmp_path):
    """Velocity Verlet's error in the pulse's speed is of order (dt/τ)², so a bead's arrival error
    grows with the time t the pulse took to reach it. Along a chain, whose solitary wave keeps the
    struck bead's contact time, every bead's error is within (0.40 τ + 0.252 t)/N² (measured; the
    constants of hexdem compare's tolerances round them up), LAMMPS early, at second order bead by
    bead; the far beads' errors are many times the near ones'."""
    study = study_time_step(CHAIN, (80, STEPS_PER_CONTACT, 280), tmp_path)
    growth = arrival_growth(study)
    assert 0.8 * ARRIVAL_ERROR_N2 < growth.floor <= ARRIVAL_ERROR_N2, growth
    assert 0.95 * ARRIVAL_GROWTH_N2 < growth.rate <= ARRIVAL_GROWTH_N2, growth
    coarse, default = study.runs[0], study.at(STEPS_PER_CONTACT)
    reached = study.arrivals > 0
    assert np.all(default.arrival_errors[reached] < 0)
    np.testing.assert_allclose(
        coarse.arrival_errors[reached] * 80**2, default.arrival_errors[reached] * STEPS_PER_CONTACT**2, rtol=0.02
    )
    near, far = (
        np.abs(default.arrival_errors[study.arrivals == t]).item() for t in np.sort(study.arrivals[reached])[[0, -1]]
    )
    assert far > 30 * near


def test_the_growth_is_scaled_for_a_second_order_engine():
    with pytest.raises(HexdemError, match="second-order engine, not reference's order 4"):
        arrival_growth(Convergence("reference", 4, (), (), 0, np.array([])))


def test_the_reference_converges_faster_and_meets_the_target_at_the_default(tmp_path):
    study = study_time_step(RunConfig(engine="reference"), (80, STEPS_PER_CONTACT, 280, 560), tmp_path)
    assert study.observed_orders[-1] > 3.0, study.observed_orders
    default = study.at(STEPS_PER_CONTACT)
    assert default.peak_error < 1e-6 and default.arrival_error < 1e-3 * ARRIVAL_TARGET_S
    assert math.isfinite(default.energy_drift) and default.energy_drift < 1e-6


def test_the_default_sampling_leaves_the_step_inside_the_target(tmp_path):
    """The default run sampled every τ/20 against sampling every step (the same trajectory):
    its sampling error plus the step's (the second-order LAMMPS study) stays inside the target,
    and the parabolic half-maximum crossing keeps the arrivals' share small."""
    sampled = sampling_error(RunConfig(), tmp_path)
    assert sampled.dump_every == STEPS_PER_CONTACT // SAMPLES_PER_CONTACT and sampled.n_beads >= 20
    step = study_time_step(RunConfig(), (80, STEPS_PER_CONTACT, 280), tmp_path / "steps").at(STEPS_PER_CONTACT)
    assert step.peak_error + sampled.peak_error < PEAK_TARGET
    assert step.arrival_error + sampled.arrival_error < ARRIVAL_TARGET_S
    assert sampled.arrival_error < 0.3 * ARRIVAL_TARGET_S
