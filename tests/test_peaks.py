"""Pulse definitions (hexdem.analysis.peaks) on pulses whose peak and half-maximum are known exactly."""

import numpy as np
import pytest

from hexdem.analysis.peaks import pulse_times, refine_peak, refine_peaks


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


def test_record_ending_before_the_peak_is_nan_and_a_silent_bead_peaks_at_zero():
    """Still rising at the end: no peak is known. Never moved: the peak is 0, and it has no time."""
    times = np.linspace(0, 1e-4, 101)
    rising = hertz_like_pulse(times, 1.2e-4, 6e-5, 0.1)
    result = pulse_times(times, np.column_stack([rising, np.zeros_like(times)]))
    assert np.all(np.isnan([result.peak_speed[0], result.t_peak[0], result.arrival_time[0]]))
    assert result.peak_speed[1] == 0.0 and np.isnan(result.t_peak[1]) and np.isnan(result.arrival_time[1])


def test_initial_velocity_is_its_own_peak_at_time_zero():
    times = np.linspace(0, 1e-4, 101)
    falling = 0.4 * np.exp(-times / 2e-5)
    assert refine_peak(times, falling) == (0.0, 0.4)
    result = pulse_times(times, falling[:, None])
    assert result.arrival_time[0] == 0.0


def test_many_windows_at_once_equal_one_window_at_a_time():
    """Noisy Gaussian pulses whose largest sample is the middle one: the batched refinement gives
    the same peaks and times of peak as refine_peak window by window, to round-off."""
    rng = np.random.default_rng(0)
    knots = np.arange(-3.0, 4.0)
    windows = []
    while len(windows) < 300:
        centre, width = rng.uniform(-0.5, 0.5), rng.uniform(0.6, 3.0)
        window = rng.uniform(0.5, 2.0) * np.exp(-((knots - centre) / width) ** 2) + rng.normal(0.0, 0.01, 7)
        if np.argmax(window) == 3:
            windows.append(window)
    interval = 2.5e-6
    offset, peaks = refine_peaks(np.array(windows), interval)
    expected = np.array([refine_peak(knots * interval, window) for window in windows])
    np.testing.assert_allclose(peaks, expected[:, 1], rtol=1e-13)
    np.testing.assert_allclose(offset, expected[:, 0], rtol=0, atol=1e-13 * interval)
    flat = np.full((1, 7), 1.0)  # a plateau: the middle sample is the peak
    assert refine_peaks(flat, interval)[1][0] == pytest.approx(1.0)
    assert [len(a) for a in refine_peaks(np.empty((0, 7)), interval)] == [0, 0]  # no bead has peaked yet
