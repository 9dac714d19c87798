"""Pulse definitions (hexdem.analysis.peaks) on pulses whose peak and half-maximum are known exactly."""

import numpy as np
import pytest

from hexdem.analysis.peaks import pulse_times, refine_peak


def hertz_like_pulse(t, centre, width, height):
    """A smooth compact pulse: height·cos²(π(t − centre)/(2·width)) on |t − centre| < width."""
    phase = (t - centre) / width
    return np.where(np.abs(phase) < 1, height * np.cos(np.pi * phase / 2) ** 2, 0.0)


@pytest.mark.parametrize("step", [1e-6, 5e-6])
def test_peak_and_half_maximum_between_samples(step):
    times = np.arange(0, 4e-4, step)
    centre, width, height = 1.234567e-4, 6e-5, 0.1
    speeds = np.column_stack([hertz_like_pulse(times, centre, width, height),
                              hertz_like_pulse(times, 2 * centre, width, height / 3)])
    result = pulse_times(times, speeds)
    np.testing.assert_allclose(result.peak_speed, [height, height / 3], rtol=2e-4)
    np.testing.assert_allclose(result.t_peak, [centre, 2 * centre], atol=0.05 * step)
    half = np.array([centre, 2 * centre]) - width / 2
    np.testing.assert_allclose(result.arrival_time, half, atol=0.05 * step)


def test_record_ending_before_the_peak_and_silent_beads_are_nan():
    times = np.linspace(0, 1e-4, 101)
    rising = hertz_like_pulse(times, 1.2e-4, 6e-5, 0.1)
    result = pulse_times(times, np.column_stack([rising, np.zeros_like(times)]))
    assert np.all(np.isnan([result.peak_speed, result.t_peak, result.arrival_time]))


def test_initial_velocity_is_its_own_peak_at_time_zero():
    times = np.linspace(0, 1e-4, 101)
    falling = 0.4 * np.exp(-times / 2e-5)
    assert refine_peak(times, falling) == (0.0, 0.4)
    result = pulse_times(times, falling[:, None])
    assert result.arrival_time[0] == 0.0
