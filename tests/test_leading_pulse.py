"""The leading pulse's amplitude (hexdem.analysis.leading_pulse) on signals of known shape."""

import numpy as np
import pytest

from hexdem.analysis.leading_pulse import leading_pulse_amplitude

T = np.linspace(0.0, 10.0, 201)


def pulse(t0, amplitude, width=0.4):
    return amplitude * np.exp(-0.5 * ((T - t0) / width) ** 2)


def test_a_weaker_leading_pulse_is_found_before_a_larger_later_one():
    signal = pulse(3.0, 0.5) + pulse(6.0, 1.0)
    lead = leading_pulse_amplitude(signal[:, None])[0]
    assert lead == pytest.approx(0.5, rel=1e-3)
    assert signal.max() == pytest.approx(1.0, rel=1e-3)


def test_the_parabola_vertex_corrects_for_the_sampling_grid():
    """A Gaussian whose top falls between samples: the vertex is closer than the largest sample."""
    signal = pulse(5.025, 1.0)
    lead = leading_pulse_amplitude(signal[:, None])[0]
    assert abs(lead - 1.0) < 0.2 * abs(signal.max() - 1.0)


def test_a_small_wiggle_does_not_end_the_pulse_and_a_weak_precursor_is_ignored():
    rising = pulse(5.0, 1.0, width=1.0) * (1 + 0.05 * np.sin(40 * T))  # wiggles of 10 %
    precursor = pulse(2.0, 0.1)  # below 20 % of the largest speed
    lead = leading_pulse_amplitude((rising + precursor)[:, None])[0]
    assert lead == pytest.approx(np.max(rising), rel=2e-3)


def test_signals_without_a_complete_leading_pulse_give_nan():
    still = np.zeros_like(T)
    growing = T / T[-1]
    at_the_end = pulse(10.0, 1.0)
    columns = np.column_stack([still, growing, at_the_end, pulse(5.0, 0.7)])
    lead = leading_pulse_amplitude(columns)
    assert np.isnan(lead[:3]).all() and lead[3] == pytest.approx(0.7, rel=1e-3)
