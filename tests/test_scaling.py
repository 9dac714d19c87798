"""Scaling laws of Sec. V: fit machinery on synthetic data, the paper's forms, a real tiny sweep."""

import json

import numpy as np
import pytest
from scipy.optimize import curve_fit

from hexdem.cli.main import main
from hexdem.errors import HexdemError
from hexdem.theory import outputs as scaling_outputs
from hexdem.theory import scaling, sweep

V0 = np.linspace(0.01, 0.30, 30)
TRUE = {"m": 0.21, "b": 0.84, "amplitude": {1: (0.2, 0.63), 2: (-0.4, 0.05, 0.2)}}


def synthetic_peaks(combination, n_beads=14, noise=0.0, rng=None):
    """Peaks that follow the combination's law exactly, times log-normal noise."""
    law = scaling.ScalingLaw(
        combination.name, combination.start, TRUE["m"], TRUE["b"], TRUE["amplitude"][combination.degree]
    )
    n = np.arange(n_beads)
    peaks = law(V0[:, None], n[None, :])
    if noise:
        peaks = peaks * np.exp(noise * rng.standard_normal(peaks.shape))
    return peaks


@pytest.mark.parametrize("name", list(scaling.COMBINATIONS))
@pytest.mark.parametrize("kind", scaling.FIT_KINDS)
def test_sweep_fits_recover_known_m_b_and_amplitude(name, kind):
    combination = scaling.COMBINATIONS[name]
    fit = scaling.fit_combination(combination, V0, synthetic_peaks(combination), last=12, kind=kind)
    assert fit.rate["m"] == pytest.approx(TRUE["m"], rel=1e-9)
    assert fit.rate["b"] == pytest.approx(TRUE["b"], rel=1e-9)
    np.testing.assert_allclose(fit.ratio.values, TRUE["amplitude"][combination.degree], rtol=1e-8, atol=1e-10)
    assert fit.rate.error("m") < 1e-9


def test_sensitivity_table_covers_every_window_and_fit_type():
    combination = scaling.COMBINATIONS["0/0"]
    rows = scaling.sensitivity(combination, V0, synthetic_peaks(combination))
    assert [(r["last"], r["fit"]) for r in rows] == [
        (last, kind) for last in range(4, 14) for kind in scaling.FIT_KINDS
    ]
    np.testing.assert_allclose([r["m"] for r in rows], TRUE["m"], rtol=1e-8)
    np.testing.assert_allclose([r["b"] for r in rows], TRUE["b"], rtol=1e-9)


def test_standard_errors_match_the_scatter_of_repeated_noisy_sweeps():
    combination, rng = scaling.COMBINATIONS["30/30"], np.random.default_rng(7)
    fits = [
        scaling.fit_combination(combination, V0, synthetic_peaks(combination, noise=0.01, rng=rng), last=12)
        for _ in range(300)
    ]
    m = np.array([f.rate["m"] for f in fits])
    assert abs(m.mean() - TRUE["m"]) < 3 * m.std() / np.sqrt(len(m))
    assert np.mean([f.rate.error("m") for f in fits]) == pytest.approx(m.std(), rel=0.2)


def test_stderr_of_c_is_conditional_on_the_measured_start_bead():
    """V_start is the measured peak (not a fit parameter): with an exact start bead the
    stderr of c matches the scatter of c."""
    combination, rng = scaling.COMBINATIONS["30/30"], np.random.default_rng(3)
    exact = synthetic_peaks(combination)
    c = []
    for _ in range(300):
        noisy = synthetic_peaks(combination, noise=0.01, rng=rng)
        noisy[:, combination.start] = exact[:, combination.start]
        c.append(scaling.fit_decay(np.arange(14), noisy[0], combination.start, 12))
    c = np.array(c)
    assert np.mean(c[:, 1]) == pytest.approx(c[:, 0].std(), rel=0.2)


def test_polynomial_fit_follows_curve_fit_conventions():
    rng = np.random.default_rng(1)
    x = np.linspace(0, 1, 12)
    y = 1.0 - 2.0 * x + 0.5 * x**2 + 0.01 * rng.standard_normal(12)
    fit = scaling.polynomial_fit(x, y, 2, ("alpha", "beta", "gamma"))
    popt, pcov = curve_fit(lambda t, a, b, c: a * t**2 + b * t + c, x, y)
    np.testing.assert_allclose(fit.values, popt, rtol=1e-7)
    np.testing.assert_allclose(fit.covariance, pcov, rtol=1e-5)
    assert fit["gamma"] == pytest.approx(popt[2], rel=1e-7)


def test_laws_are_the_papers_equations():
    m, b = 0.2, 0.85
    v0, n = np.array([0.05, 0.2]), np.arange(3, 9)[:, None]
    for name, combination in scaling.COMBINATIONS.items():
        amplitude = (0.3, 0.6) if combination.degree == 1 else (-0.4, 0.1, 0.5)
        law = scaling.ScalingLaw(name, combination.start, m, b, amplitude)
        a = amplitude
        paper = {
            "v30": lambda: v0 * (a[0] * v0 + a[1]) * (m * v0 + b) ** (n - 1),
            "v0": lambda: v0 * (a[0] * v0**2 + a[1] * v0 + a[2]) * (m * v0 + b) ** (n - 2),
            "veq0": lambda: v0 * (a[0] * v0**2 + a[1] * v0 + a[2]) * (m * v0 + b) ** (n - 1),
        }[combination.equation]
        np.testing.assert_allclose(law(v0, n), paper(), rtol=1e-14)
    assert {c.equation for c in scaling.COMBINATIONS.values()} == {"v30", "v0", "veq0"}
    assert [c.start for c in scaling.COMBINATIONS.values()] == [
        1 if c.line == "+30" else 2 for c in scaling.COMBINATIONS.values()
    ]


@pytest.mark.parametrize("amplitude", [(0.3, 0.6), (-0.4, 0.1, 0.5)])
def test_physical_law_is_the_nondimensional_one_with_v_replaced_by_v_over_u(amplitude):
    law, unit = scaling.ScalingLaw("x", 1, 0.2, 0.85, amplitude), 4106.0
    physical = law.physical(unit)
    v0_m_s = np.array([0.25, 0.4, 0.7])
    np.testing.assert_allclose(physical(v0_m_s, 6), unit * law(v0_m_s / unit, 6), rtol=1e-13)
    np.testing.assert_allclose(physical.decay_rate(v0_m_s), law.decay_rate(v0_m_s / unit), rtol=1e-14)


def test_geometric_and_power_data_are_told_apart():
    n = np.arange(0, 14).astype(float)
    geometric = scaling.decay_form_test(0.3 * 0.87**n, 1, 12)
    assert geometric.verdict == "geometric" and geometric.q == pytest.approx(0.87)
    assert abs(geometric.drift_fraction) < 1e-6
    power = scaling.decay_form_test(0.3 * np.maximum(n, 1) ** -0.5, 1, 12)
    assert power.verdict == "power" and power.p == pytest.approx(0.5)
    assert power.drift_fraction == pytest.approx(1.0)


def test_fit_windows_are_validated():
    combination = scaling.COMBINATIONS["0/0"]
    peaks = synthetic_peaks(combination)
    with pytest.raises(HexdemError, match="the window's last bead must lie in .*got 3"):
        scaling.fit_combination(combination, V0, peaks, last=3)
    with pytest.raises(HexdemError, match="the window's last bead must lie in .*got 14"):
        scaling.fit_combination(combination, V0, peaks, last=14)
    with pytest.raises(HexdemError, match="unknown fit type 'cubic'"):
        scaling.fit_decay(np.arange(14), peaks[0], 2, 10, kind="cubic")
    with pytest.raises(HexdemError, match="at least 4 values of V0"):
        sweep.SweepSettings(n_v0=3)


def test_larger_hexagon_gives_identical_peaks():
    """No walls, no tension: the packing's far edges cannot reach the fitted beads in time."""
    settings = sweep.SweepSettings(last=6, duration_contacts=9.0, workers=1)
    small = sweep.run_one(settings, 0.3, 0.0)
    large = sweep.run_one(sweep.SweepSettings(last=6, duration_contacts=9.0, edge_beads=14, workers=1), 0.3, 0.0)
    for line in ("0", "+30"):
        assert np.all(np.isfinite(small.peaks[line][:7]))
        np.testing.assert_allclose(small.peaks[line][:7], large.peaks[line][:7], rtol=1e-9)  # summation order


def test_scaling_command_writes_the_four_laws(tmp_path, capsys):
    out = tmp_path / "scaling"
    status = main(
        [
            "scaling",
            "--out",
            str(out),
            "--n-v0",
            "4",
            "--v0-max",
            "0.2",
            "--last",
            "5",
            "--duration",
            "8",
            "--workers",
            "1",
        ]
    )
    assert status == 0
    summary = json.loads((out / "scaling.json").read_text())
    for name, combination in scaling.COMBINATIONS.items():
        entry = summary[name]
        assert entry["start_bead"] == combination.start and entry["window"] == [combination.start, 5]
        assert entry["v0_range"] == [0.01, 0.2]
        assert (entry["gamma"] is None) == (combination.degree == 1)
        assert set(entry["stderr"]) == {"m", "b", "alpha", "beta", "gamma"}
        assert 0.7 < entry["b"] < 1.0, "peaks decay along the line"
    for name in scaling_outputs.OUTPUT_FILES:
        assert (out / name).stat().st_size > 0
    header = (out / "peaks.csv").read_text().splitlines()[0].split(",")
    assert header[-1] == "warnings" and summary["sweep"]["runs_that_warned"] == []


def test_a_run_whose_fit_window_peaks_within_a_contact_time_of_its_end_warns():
    """The study's table names a run whose window's last peaks came late (cut short) or never."""
    assert sweep.window_warnings({"0": np.array([1.0, 2.0]), "+30": np.array([1.5, 6.9])}, 8.0, 1.0) == ()
    assert sweep.window_warnings({"0": np.array([1.0, 7.2]), "+30": np.array([1.5])}, 8.0, 1.0) == (
        "window_peak_near_end",
    )
    assert sweep.window_warnings({"0": np.array([1.0, np.nan])}, 8.0, 1.0) == ("window_peak_near_end",)
    late = sweep.run_one(sweep.SweepSettings(last=6, duration_contacts=4.0, workers=1), 0.3, 0.0)
    assert late.warnings == ("window_peak_near_end",)
