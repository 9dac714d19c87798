"""Pulse definitions (hexdem.analysis.peaks) on pulses whose peak and half-maximum are known exactly,
in the whole record and in the tracker, and a dimer chain in LAMMPS against an independent integrator."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import hexdem.common.kernel_switch as compiled
from hexdem.analysis.peaks import PEAK_OVERSHOOT, pulse_times, refine_peak, refine_peaks
from hexdem.analysis.tracker import PulseTracker
from hexdem.engines.sampling import Sample
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.model.granular import RunSettings
from hexdem.model.materials import hertz_stiffness
from hexdem.model.model_builder import build_model


def hertz_like_pulse(t, centre, width, height):
    """A smooth compact pulse: height·cos²(π(t − centre)/(2·width)) on |t − centre| < width."""
    phase = (t - centre) / width
    return np.where(np.abs(phase) < 1, height * np.cos(np.pi * phase / 2) ** 2, 0.0)


@pytest.mark.parametrize("step", [1e-6, 5e-6])
def test_peak_and_half_maximum_between_samples(step):
    times = np.arange(0, 4e-4, step)
    centre, width, height = 1.234567e-4, 6e-5, 0.1
    speeds = np.column_stack(
        [hertz_like_pulse(times, centre, width, height), hertz_like_pulse(times, 2 * centre, width, height / 3)]
    )
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
        window = rng.uniform(0.5, 2.0) * np.exp(-(((knots - centre) / width) ** 2)) + rng.normal(0.0, 0.01, 7)
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


def two_maxima(t, narrow_first: bool):
    """A broad maximum (height 1, 20 samples wide) on a sample and a narrow one 0.2 % higher (7 samples
    wide) half-way between two samples, whose samples lie 0.3 % below the broad one's: the largest
    sample belongs to the lower maximum. ``narrow_first``: the narrow one comes first (its window is
    then a complete running maximum that the broad one's largest sample replaces), else second (a
    rival below the running maximum)."""
    narrow, broad = (30.5, 80.0) if narrow_first else (80.5, 30.0)
    return 1.002 * np.exp(-(((t - narrow) / 7) ** 2)) + np.exp(-(((t - broad) / 20) ** 2))


@pytest.mark.parametrize("narrow_first", [True, False], ids=["narrow-first", "narrow-second"])
def test_the_peak_is_the_largest_maximum_of_the_interpolant(monkeypatch, narrow_first):
    """The whole record and the tracker (NumPy and compiled) find the narrow maximum, between samples,
    not the one around the largest sample; the arrival is where the speed first reaches half of it."""
    times = np.arange(120.0)
    speeds = two_maxima(times, narrow_first)
    fine = np.linspace(0, 119, 1_190_001)
    dense = two_maxima(fine, narrow_first)
    true_peak, true_time = dense.max(), fine[np.argmax(dense)]
    assert speeds.max() < true_peak / (1 + 2e-3) and not abs(times[np.argmax(speeds)] - true_time) < 40
    whole = pulse_times(times, speeds[:, None])
    assert whole.peak_speed[0] == pytest.approx(true_peak, rel=1e-5)
    assert whole.t_peak[0] == pytest.approx(true_time, abs=0.05)
    assert whole.arrival_time[0] == pytest.approx(fine[np.argmax(dense >= 0.5 * whole.peak_speed[0])], abs=0.05)
    assert refine_peak(times, speeds) == (whole.t_peak[0], whole.peak_speed[0])
    paths = []
    for compiled_way in (False, True):
        monkeypatch.setattr(compiled, "COMPILED", compiled_way)
        paths.append(tracked_speeds(times, np.column_stack([speeds, speeds[::-1]])))
    for name in ("peak_speed", "t_peak", "arrival_time", "reach_time"):
        np.testing.assert_array_equal(getattr(paths[1], name), getattr(paths[0], name), err_msg=name)
    assert paths[0].peak_speed[0] == pytest.approx(whole.peak_speed[0], rel=1e-12)
    assert paths[0].t_peak[0] == pytest.approx(whole.t_peak[0], abs=1e-10)
    assert paths[0].arrival_time[0] == pytest.approx(whole.arrival_time[0], abs=0.05)
    reversed_whole = pulse_times(times, speeds[::-1, None])  # the other order, in the same run
    assert paths[0].peak_speed[1] == pytest.approx(reversed_whole.peak_speed[0], rel=1e-12)
    assert paths[0].t_peak[1] == pytest.approx(reversed_whole.t_peak[0], abs=1e-10)


def test_a_lower_maximum_beyond_the_overshoot_is_not_a_rival():
    """A local maximum further than PEAK_OVERSHOOT below the largest sample is not refined: its
    spline cannot reach the largest sample at the runs' sampling."""
    times = np.arange(120.0)
    speeds = np.exp(-(((times - 30) / 20) ** 2)) + (1 - 2 * PEAK_OVERSHOOT) * np.exp(-(((times - 80.5) / 7) ** 2))
    assert refine_peak(times, speeds)[0] == pytest.approx(30.0, abs=0.05)


class _NoAudit:
    """Synthetic speeds: no mechanics to audit (one region, a constant energy)."""

    region_names = ["all"]

    def part(self, bodies, n_own, positions, velocities, angular_velocities=None):
        return np.array([1.0, 0.0, 0.0, 0.0, 0.0])


def tracked_speeds(times, speeds):
    """The tracker's peaks, times of peak and arrivals of ``speeds`` (n_samples, 2), fed as the
    speeds of a two-bead chain sampled at ``times``."""
    model = build_model(RunConfig(shape="chain", beads=speeds.shape[1]))
    run = PulseTracker(model, RunSettings(dt_s=times[1], n_steps=len(times) - 1, dump_every=1))
    run.audit = _NoAudit()
    ids = np.arange(1, speeds.shape[1] + 1)
    for s, row in enumerate(speeds):
        run(Sample(s, s, times[s], ids, np.zeros((len(ids), 2)), np.column_stack([row, np.zeros(len(ids))])))
    return run.finish()


def chain_speeds(config: RunConfig, times):
    """|v| (len(times), beads) of a free chain struck at bead 0 at V0, integrated apart from hexdem:
    F = k_n sqrt(R_eff) δ^(3/2) between neighbours (k_n = 4/3 E*, R_eff = r_i r_j / (r_i + r_j)), m = ρπd³/6,
    SciPy's DOP853 at rtol 1e-12."""
    model = build_model(config)
    d = np.asarray(config.diameters_m)
    masses = model.masses_kg[: len(d)]
    material = config.material(config.bead_material)
    reduced = d[:-1] * d[1:] / (2 * (d[:-1] + d[1:]))
    prefactor = hertz_stiffness(material, material) * np.sqrt(reduced)

    def rates(t, y):
        x, v = np.split(y, 2)
        force = prefactor * np.maximum(x[:-1] - x[1:], 0.0) ** 1.5
        return np.concatenate([v, (np.append(0.0, force) - np.append(force, 0.0)) / masses])

    start = np.zeros(2 * len(d))
    start[len(d)] = config.v0
    solution = solve_ivp(rates, (0.0, times[-1]), start, method="DOP853", rtol=1e-12, atol=1e-16, t_eval=times)
    return np.abs(solution.y[len(d) :].T)


def test_a_dimer_chains_peaks_are_the_integrators(tmp_path):
    """A dimer chain of steel beads of 19.05 and 12.7 mm (mass ratio 0.30): its light bead 3 has two
    maxima 2.9e-4 apart, the narrow higher one between samples (it was reported 2.7e-4 low, the
    spline placed around the broad one's largest sample). Every bead's peak is the integrator's
    (sampled every 3 ns) to 2e-4 (measured 5.1e-5), its time of peak and its arrival (half of the
    peak first reached) to 0.05 µs (measured 7 and 5 ns): LAMMPS's velocity Verlet at 140 steps per
    contact, not the analysis, sets what is left."""
    beads = 20
    config = RunConfig(shape="chain", beads=beads, diameters_m=[0.01905, 0.0127] * (beads // 2))
    r = simulate(config, tmp_path).results
    duration = r.t_peak[np.isfinite(r.t_peak)].max() + 1e-5
    times = np.linspace(0.0, duration, int(duration / 3e-9) + 1)
    speeds = chain_speeds(config, times)
    peak = speeds.max(axis=0)
    seen = np.isfinite(r.peak_speed)
    assert seen.sum() >= beads - 2, "only the chain's last beads may still be rising at the run's end"
    np.testing.assert_allclose(r.peak_speed[seen], peak[seen], rtol=2e-4, atol=0)
    sharp = seen & (np.arange(beads) < beads - 2)  # the far end's two beads leave at their peak: a flat maximum
    np.testing.assert_allclose(r.t_peak[sharp], times[np.argmax(speeds, axis=0)][sharp], rtol=0, atol=5e-8)
    half = np.array([times[np.argmax(speeds[:, b] >= 0.5 * peak[b])] for b in range(beads)])
    np.testing.assert_allclose(r.arrival_time[seen], half[seen], rtol=0, atol=5e-8)
    light = speeds[:, 3]
    inner = np.flatnonzero((light[1:-1] > light[:-2]) & (light[1:-1] >= light[2:])) + 1
    assert np.sum(light[inner] > (1 - 1e-3) * peak[3]) == 2, "bead 3 has two nearly equal maxima"
