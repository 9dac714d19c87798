"""``hexdem calibrate``: its statistics against analytic posteriors, its reduction against analytic
pulses, its refusals, and a whole calibration on synthetic records resumed after ``kill -9``."""

import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy import stats
from scipy.stats import qmc

from hexdem.calibration import diagnostics, inference, nuisance, sampler
from hexdem.calibration.emulator import Emulator
from hexdem.calibration.observables import FOOT_SAMPLES, Record, lead_in, noise_covariance, reduce_record
from hexdem.calibration.packings import SIGMA_LEVELS, on_sigma_levels, preparation_of, settled_packing
from hexdem.calibration.priors import NORMAL_TAIL, Prior
from hexdem.calibration.report import summarize
from hexdem.calibration.simulations import Problem, simulate_point
from hexdem.calibration.spread import RECORD_TAIL_DOF, Spread, variance_ratio
from hexdem.calibration.synthetic import model_error_applied, synthetic_rows, write_measured
from hexdem.cli.main import main
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.materials import PAPER_DIAMETER_M
from hexdem.model.model_builder import build_model

TINY = {"edge_beads": 5, "sensors": ["0:1", "0:3"]}
TINY_TOML = 'edge_beads = 5\nsensors = ["0:1", "0:3"]\n'
TRUE_V0 = 0.43
TRUE_SIGMA_M = 7.62e-5  # the paper's 6 tol


def test_priors_map_the_unit_cube_onto_their_distributions():
    uniform, loguniform = Prior("v0", "uniform", 0.2, 0.7), Prior("x", "loguniform", 1e8, 1e12)
    normal = Prior("y", "normal", 3.0, 0.5)
    assert uniform.from_unit(0.5) == pytest.approx(0.45)
    assert loguniform.from_unit(0.5) == pytest.approx(1e10)  # the median of a log-uniform is √(ab)
    assert normal.from_unit(0.5) == pytest.approx(3.0)
    assert normal.from_unit(stats.norm.cdf(1.0)) == pytest.approx(3.5, rel=1e-3)
    assert normal.support == (3.0 - NORMAL_TAIL * 0.5, 3.0 + NORMAL_TAIL * 0.5)
    values = np.array([0.25, 0.5, 0.66])
    assert uniform.from_unit(uniform.to_unit(values)) == pytest.approx(values)


def test_the_emulator_interpolates_a_smooth_response_and_knows_its_error():
    def response(u):
        return np.column_stack([np.sin(3 * u[:, 0]) + u[:, 1] ** 2, np.exp(u[:, 0] - u[:, 1])])

    train = qmc.LatinHypercube(2, seed=1).random(40)
    test = qmc.LatinHypercube(2, seed=2).random(200)
    mean, variance = Emulator(train, response(train)).predict(test)
    error = mean - response(test)
    assert np.max(np.abs(error)) < 5e-3
    z = error / np.sqrt(variance + 1e-30)
    assert np.mean(np.abs(z) < 3.0) > 0.9  # its variance is an honest error bar, not a guess


def test_a_linear_gaussian_model_gives_the_analytic_posterior():
    """y = A u + b with Gaussian noise and a prior that is flat where the likelihood lives: the
    posterior is N(m, S), S = (Aᵀ Σ⁻¹ A)⁻¹, m = S Aᵀ Σ⁻¹ (y − b) (two records: their sum)."""
    a, b = np.array([[2.0, 1.0], [0.5, -1.5], [1.0, 1.0]]), np.array([0.1, 0.2, -0.3])
    noise = np.diag([0.02, 0.03, 0.025]) ** 2
    truth = np.array([0.45, 0.55])
    rng = np.random.default_rng(3)
    records = np.array([a @ truth + b + rng.multivariate_normal(np.zeros(3), noise) for _ in range(2)])
    data = inference.Data(records, np.array([noise, noise]), ("a", "b", "c"))
    points = inference.design(2, 30, seed=4)
    observables = (points @ a.T + b)[:, None, :]
    fit = inference.fit_stage(data, points, observables, seed=5)
    precision = 2 * a.T @ np.linalg.inv(noise) @ a
    covariance = np.linalg.inv(precision)
    mean = covariance @ a.T @ np.linalg.inv(noise) @ (records - b).sum(axis=0)
    sd = np.sqrt(np.diag(covariance))
    assert np.abs(fit.samples.mean(axis=0) - mean) == pytest.approx(0, abs=0.15 * sd.min())
    assert fit.samples.std(axis=0) == pytest.approx(sd, rel=0.12)
    assert np.corrcoef(fit.samples, rowvar=False)[0, 1] == pytest.approx(covariance[0, 1] / sd.prod(), abs=0.08)


def test_correlated_parameters_are_reported_as_trading_off():
    rng = np.random.default_rng(0)
    x = rng.uniform(0.3, 0.6, 4000)
    samples = np.column_stack([x, 1.0 - x + rng.normal(0, 0.005, x.size)])
    priors = [Prior("v0", "uniform", 0.2, 0.7), Prior("restitution", "uniform", 0.3, 0.99)]
    notes = summarize(priors, samples)["identifiability"]
    assert any("v0 and restitution trade off" in note for note in notes)


def test_the_directions_the_data_measure_are_named_and_a_key_left_at_its_prior_is_said():
    """Unit-cube samples along a line u_e = 1 − u_v (sd 0.005 across it) and a third key uniform:
    the best-measured direction is (u_v + u_e)/√2, to (0.005/√2) / (1/√12) of its prior's spread; the
    third key's direction keeps the prior's spread, and the notes say the data leave it there."""
    rng = np.random.default_rng(0)
    along = rng.uniform(0.2, 0.8, 20000)
    unit = np.column_stack([along, 1.0 - along + rng.normal(0, 0.005, along.size), rng.uniform(0, 1, along.size)])
    priors = [
        Prior("v0", "uniform", 0.2, 0.7),
        Prior("restitution", "uniform", 0.3, 0.99),
        Prior("friction", "uniform", 0.0, 1.0),
    ]
    samples = np.column_stack([prior.from_unit(unit[:, j]) for j, prior in enumerate(priors)])
    summary = summarize(priors, samples)
    best = summary["directions"][0]
    assert [best["combination"][key] for key in ("v0", "restitution")] == pytest.approx([2**-0.5] * 2, abs=0.01)
    assert best["sd_over_prior"] == pytest.approx(0.005 / np.sqrt(2) * np.sqrt(12), rel=0.05)
    assert summary["directions"][-1]["sd_over_prior"] == pytest.approx(1.0, abs=0.03)
    assert "the data leave friction at its prior: no direction they measure involves it" in summary["identifiability"]


class _Fixed:
    """An emulator and a spread that return fixed values at every point."""

    def __init__(self, mean, variance, spread, realizations):
        self.mean, self.variance, self.value, self.realizations = mean, variance, spread, realizations
        self.x = np.zeros((1, 1))  # simulated at one parameter

    def predict(self, unit):
        return np.tile(self.mean, (len(unit), 1)), np.tile(self.variance, (len(unit), 1))

    def __call__(self, unit):
        return np.tile(self.value, (len(unit), 1, 1))

    def scale(self, unit):
        """The spread's scale, 1 at every coordinate (the spread as given)."""
        return np.ones(len(unit))

    def record_scale(self, unit):
        """Each record's packing scale: 1 + 4 u at its coordinate u."""
        return 1 + 4 * np.asarray(unit)


def test_the_likelihood_is_the_joint_gaussian_of_records_that_share_the_emulators_error():
    """Records y_r = μ + e + δ_r + ε_r with e ~ N(0, diag s² + (π/2) Σ_K/K) common to all (the
    error of the median of K packings) and δ_r ~ N(0, λ_r Σ_K): the stacked records are
    N(1 ⊗ μ, blockdiag(Σ_r + λ_r Σ_K) + 11ᵀ ⊗ C),
    whose density the likelihood must be (up to the constant −(R m / 2) log 2π that it leaves out),
    each record's λ_r at its own coordinate after the spread's scale."""
    rng = np.random.default_rng(2)
    m, r, k = 3, 4, 8
    mean, variance = rng.normal(size=m), rng.uniform(0.01, 0.05, m)
    a = rng.normal(size=(m, m))
    spread = 0.02 * a @ a.T
    covariances = np.array([np.diag(rng.uniform(0.01, 0.03, m)) for _ in range(r)])
    records = mean + rng.normal(0, 0.3, (r, m))
    likelihood = inference.Likelihood(
        inference.Data(records, covariances, ("a", "b", "c")),
        _Fixed(mean, variance, spread, k),
        _Fixed(mean, variance, spread, k),
    )
    common = np.diag(variance) + np.pi / 2 * spread / k
    coordinates = np.array([0.0, 0.25, 0.5, 1.0])
    scales = 1 + 4 * coordinates
    joint = np.kron(np.ones((r, r)), common)
    for i in range(r):
        joint[i * m : (i + 1) * m, i * m : (i + 1) * m] += covariances[i] + scales[i] * spread
    residual = (records - mean).ravel()
    expected = -0.5 * (residual @ np.linalg.solve(joint, residual) + np.linalg.slogdet(joint)[1])
    assert likelihood.dimension == 2 + r  # the spread's scale and the records' after the parameter
    point = np.r_[0.5, 0.5, coordinates]
    assert likelihood(point[None])[0] == pytest.approx(expected, rel=1e-10)
    together, alone = likelihood.misfit(point)
    assert together == pytest.approx(residual @ np.linalg.solve(joint, residual), rel=1e-10)
    assert alone[1] == pytest.approx(
        (records[1] - mean) @ np.linalg.solve(covariances[1] + scales[1] * spread + common, records[1] - mean),
        rel=1e-10,
    )


def test_each_records_predictive_residual_is_in_units_of_its_own_spread():
    """predictive.png's residuals: record r's observables against N(μ, Σ_r + C + λ_r Σ_K), its packing's
    scale λ_r = 1 + 4 u_r at its coordinate (C with the error (π/2) Σ_K/K of the median of K
    packings); the draws all at one point, so (y_r − μ) / √diag of that
    covariance, to the sampling error of 4000 draws (about 1 % of the standard deviation, 2 % of the
    median)."""
    rng = np.random.default_rng(3)
    m, r, k = 3, 4, 8
    mean, variance = rng.normal(size=m), rng.uniform(0.01, 0.05, m)
    spread = np.diag(rng.uniform(0.05, 0.2, m))
    covariances = np.array([np.diag(rng.uniform(0.01, 0.03, m)) for _ in range(r)])
    records = mean + rng.normal(0, 0.5, (r, m))
    fixed = _Fixed(mean, variance, spread, k)
    likelihood = inference.Likelihood(inference.Data(records, covariances, ("a", "b", "c")), fixed, fixed)
    coordinates = np.array([0.0, 0.25, 0.5, 1.0])
    draws = np.tile(np.r_[0.5, 0.5, coordinates], (4000, 1))
    residuals = diagnostics.predictive_residuals(likelihood, draws, np.random.default_rng(4))
    for i, scale in enumerate(1 + 4 * coordinates):
        sd = np.sqrt(np.diag(covariances[i] + np.diag(variance) + np.pi / 2 * spread / k + scale * spread))
        assert residuals[i] == pytest.approx((records[i] - mean) / sd, abs=0.05)


def test_the_model_discrepancy_is_a_relative_error_common_to_all_records_whose_size_is_sampled():
    """Two sensors, two records: the discrepancy δ ~ N(0, τ² diag(1, 1, t²)) is common to both, so
    the stacked records are N(1 ⊗ μ, blockdiag(Σ_r) + 11ᵀ ⊗ (diag s² + τ² W)), τ = 1e-4 (2000)^u at
    the sampler's last coordinate u."""
    m, mean, variance = 3, np.array([-1.2, -1.9, 85.0]), np.array([1e-5, 2e-5, 0.01])
    covariances = np.array([np.diag([4e-6, 9e-6, 0.04])] * 2)
    records = mean + np.array([[0.01, -0.02, 1.5], [0.012, -0.018, 1.2]])
    zero = _Fixed(mean, variance, np.zeros((m, m)), 1)
    discrepancy = nuisance.Discrepancy(2)
    likelihood = inference.Likelihood(
        inference.Data(records, covariances, ("a", "b", "c")), zero, zero, discrepancy=discrepancy
    )
    assert likelihood.dimension == 2
    for u in (0.0, 0.6, 1.0):
        tau = 1e-4 * 2000**u
        common = np.diag(variance) + tau**2 * np.diag([1.0, 1.0, mean[2] ** 2])
        joint = np.kron(np.ones((2, 2)), common) + np.kron(np.eye(2), covariances[0])
        residual = (records - mean).ravel()
        expected = -0.5 * (residual @ np.linalg.solve(joint, residual) + np.linalg.slogdet(joint)[1])
        assert likelihood(np.array([[0.5, u]]))[0] == pytest.approx(expected, rel=1e-10)
    assert discrepancy.size([0.0, 1.0]) == pytest.approx([1e-4, 0.2])


def test_the_instruments_enter_as_gains_common_to_all_records_and_a_speed_per_record():
    """Two sensors (m = 3: two log peaks, one relative arrival t). Each sensor's log gain,
    N(0, S_g²), is common to every record; each record's striker speed, v (1 + S_v z_r), moves its
    log peaks by S_v z_r and its arrival by −t S_v z_r / 5: the stacked records are
    N(1 ⊗ μ, blockdiag(Σ_r + S_v² J Jᵀ) + 11ᵀ ⊗ (diag s² + G)), J = (1, 1, −t/5). The gains given
    the records are the conditional normal of that joint Gaussian."""
    rng = np.random.default_rng(5)
    m, r, gain_sd, scatter = 3, 3, 0.03, 0.02
    mean, variance = np.array([-1.2, -1.9, 85.0]), np.array([1e-4, 2e-4, 0.05])
    covariances = np.array([np.diag([4e-6, 9e-6, 0.04]) for _ in range(r)])
    records = mean + np.array([0.0, 0.05, 0.0]) + rng.normal(0, 0.002, (r, m)) * [1, 1, 50]
    instruments = nuisance.Instruments(2, gain_sd, scatter)
    zero = _Fixed(mean, variance, np.zeros((m, m)), 1)
    likelihood = inference.Likelihood(
        inference.Data(records, covariances, ("a", "b", "c")), zero, zero, instruments=instruments
    )
    slope = np.array([1.0, 1.0, -mean[2] / 5])
    gains = np.diag([gain_sd**2, gain_sd**2, 0.0])
    common = np.diag(variance) + gains
    joint = np.kron(np.ones((r, r)), common) + np.kron(np.eye(r), scatter**2 * np.outer(slope, slope))
    joint += np.kron(np.eye(r), covariances[0])
    residual = (records - mean).ravel()
    expected = -0.5 * (residual @ np.linalg.solve(joint, residual) + np.linalg.slogdet(joint)[1])
    assert likelihood(np.array([[0.5]]))[0] == pytest.approx(expected, rel=1e-10)
    lift = np.kron(np.ones((r, 1)), gains)  # Cov(y, g)
    centre = lift.T @ np.linalg.solve(joint, residual)
    spread = gains - lift.T @ np.linalg.solve(joint, lift)
    estimate, variance_given = likelihood.log_gains(np.array([[0.5]]))
    assert estimate[0] == pytest.approx(centre[:2], rel=1e-8)
    assert variance_given[0] == pytest.approx(np.diag(spread)[:2], rel=1e-8)
    assert estimate[0, 1] - estimate[0, 0] == pytest.approx(0.05, abs=0.01)  # the second sensor reads 5 % high


def test_an_emulator_smooth_along_sigma_leaves_the_shared_packings_jumps_to_its_nugget():
    """A response linear in σ's coordinate u plus a jump of 0.3 rms at each of σ's 10 levels, the
    same for every set on a level (the K packings that all its sets share), the sets' second
    coordinate random: the ordinary emulator interpolates the jumps as if they were the response;
    the one smooth along u recovers the line, off it by about what a line fitted through 10 jumps
    errs, √(2/10) ≈ 0.45 of their rms, a little more as a process of length 1 still bends (0.51 to
    0.96 over six seeds; 0.51 at this one)."""
    rng = np.random.default_rng(2)
    levels = (np.arange(10) + 0.5) / 10
    jumps = 0.3 * rng.standard_normal(10)
    level = rng.integers(0, 10, 80)
    points = np.column_stack([levels[level], rng.random(80)])
    y = (points[:, 0] + jumps[level])[:, None]
    test = np.column_stack([levels, np.full(10, 0.5)])
    ordinary = Emulator(points, y).predict(test)[0][:, 0]
    smooth = Emulator(points, y, nugget_max=10.0, smooth=(0,)).predict(test)[0][:, 0]
    assert np.sqrt(np.mean((ordinary - levels - jumps) ** 2)) < 0.1 * np.sqrt(np.mean(jumps**2))
    assert np.sqrt(np.mean((smooth - levels) ** 2)) < 0.6 * np.sqrt(np.mean(jumps**2))


def correlated_packings(rng, n: int, k: int, rho: float) -> tuple[np.ndarray, np.ndarray]:
    """(points (n, 1), observables (n, k, 2)): μ(u) + s(u) L z over k packings, s = 0.1 + u, μ = u,
    L the Cholesky factor of two observables correlated ``rho``."""
    points = inference.design(1, n, seed=6)
    chol = np.linalg.cholesky(np.array([[1.0, rho], [rho, 1.0]]))
    return points, (0.1 + points)[:, None, :] * (rng.standard_normal((n, k, 2)) @ chol.T) + points[:, None, :]


def test_sets_that_strike_one_levels_packings_count_as_one_draw_of_them():
    """60 sets on σ's 10 levels, 40 of them at one level, each observing a flat response plus the
    error its level's packings share (sd 0.1) and a little of its own (sd 0.01): the emulator told
    the levels (``groups``) keeps the response's uncertainty at the crowded level at the size that 10
    levels' errors allow (0.1/√10 ≈ 0.03, within a factor of 2), and holds the flat response there
    to it; untold, it takes the 40 sets for 40 independent draws and claims a quarter of that."""
    rng = np.random.default_rng(12)
    sigma = np.r_[np.repeat(5 / 9, 40), np.repeat(np.arange(10) / 9, 2)]
    points = np.column_stack([sigma, rng.random(60)])
    groups = np.unique(sigma, return_inverse=True)[1]
    shared = 0.1 * rng.standard_normal(10)
    values = (shared[groups] + 0.01 * rng.standard_normal(60))[:, None]
    crowded = np.array([[5 / 9, 0.5]])
    told = Emulator(points, values, nugget_max=10.0, smooth=(0,), groups=groups).predict(crowded)
    untold = Emulator(points, values, nugget_max=10.0, smooth=(0,)).predict(crowded)
    assert np.sqrt(told[1][0, 0]) == pytest.approx(0.1 / np.sqrt(10), rel=1.0)
    assert abs(told[0][0, 0] - np.mean(shared)) < 3 * np.sqrt(told[1][0, 0])
    assert np.sqrt(untold[1][0, 0]) < 0.3 * np.sqrt(told[1][0, 0])


def test_the_spread_between_packings_follows_the_parameters():
    """Observables μ(u) + s(u) L z over K = 8 packings, s = 0.1 + u: the emulated standard
    deviations hold s within the sampling error of 80 sets of 8 (one set's log sample sd is off by
    1/√(2 (K − 1)) = 0.27, its robust scale's by 1/√0.37 times that, 0.44, the median absolute
    deviation's efficiency at the normal law being 37 %; the emulator pools the ten or so nearest
    sets, 0.14, and 3 of those are 45 %), and the pooled correlation holds L Lᵀ's ρ = 0.8 within
    4 (1 − ρ²)/√(n (K − 1)), four of its standard errors, before it is shrunk as for K − 1 = ν
    deviations of m = 2 observables: ν ρ / (ν + w), w = max(m + 1 − ν, 1) = 1."""
    n, k, rho = 80, 8, 0.8
    points, observables = correlated_packings(np.random.default_rng(5), n, k, rho)
    spread = Spread(points, observables)
    test = np.array([[0.1], [0.5], [0.9]])
    sd = np.sqrt(np.diagonal(spread(test), axis1=1, axis2=2))
    assert sd == pytest.approx(np.repeat(0.1 + test, 2, axis=1), rel=0.45)
    shrink = (k - 1) / (k - 1 + max(3 - (k - 1), 1))
    assert spread.correlation[0, 1] == pytest.approx(shrink * rho, abs=shrink * 4 * (1 - rho**2) / np.sqrt(n * (k - 1)))
    assert Spread(points, observables[:, :1])(test) == pytest.approx(0.0)


def test_the_ideal_lattice_tells_neither_centre_nor_spread_and_sigma_is_never_extrapolated():
    """Sets on σ's 10 levels from 0: at σ = 0 every packing is the ideal lattice (observables all 0),
    above it the packings differ about a centre 1 that does not move with σ (the paper's hexagon).
    The ideal lattice's sets enter neither emulator, and below the lowest disordered level (1/9 of
    the prior) the centre and the spread are that level's, 1 and 0.3 within the sampling error of
    the sets' medians and robust scales, not a trend run down to the ideal lattice's 0."""
    from hexdem.calibration.spread import disordered_range, packing_centres, robust_sd

    rng = np.random.default_rng(9)
    points = on_sigma_levels(inference.design(1, 60, seed=2), 0)
    observables = 1.0 + 0.3 * rng.standard_normal((60, 8, 2))
    observables[points[:, 0] == 0] = 0.0
    sd = robust_sd(observables, np.ones((60, 8), bool))
    held = disordered_range(points, sd, (0,))
    assert held[0][0] == pytest.approx(1 / 9) and held[1][0] == pytest.approx(1.0)
    differ = np.any(sd > 0, axis=1)
    assert (~differ).sum() == np.sum(points[:, 0] == 0) > 0
    centre = Emulator(points[differ], packing_centres(observables[differ]), smooth=(0,), held=held)
    spread = Spread(points, observables, smooth=(0,))
    for emulated, truth in (
        (centre.predict([[0.0], [0.05]])[0], 1.0),
        (np.sqrt(np.diagonal(spread([[0.0]]), axis1=1, axis2=2)), 0.3),
    ):
        assert emulated == pytest.approx(truth, rel=0.25)
    assert centre.predict([[0.0]])[0] == pytest.approx(centre.predict([[1 / 9]])[0], rel=1e-12)


def test_packings_without_a_detected_pulse_are_left_out_of_the_spread():
    """The observables of the test above, with a fifth of the packings turned into outliers 30
    standard deviations off (a sensor the pulse did not reach: a log peak of −26) and marked as
    undetected (NaN), as a simulation below the records' detection level is: the spread holds
    s = 0.1 + u within the same 45 % (its sets have fewer packings) and counts the median set's
    packings less one as its degrees of freedom. Kept, the outliers inflate a set's sample standard
    deviation more than five-fold, and the robust scale the spread takes less."""
    rng = np.random.default_rng(1)
    n, k = 80, 8
    points, observables = correlated_packings(rng, n, k, 0.8)
    scale = 0.1 + points
    lost = rng.random((n, k)) < 0.2
    observables[lost] -= 30 * scale[np.nonzero(lost)[0]]
    test = np.array([[0.1], [0.5], [0.9]])
    kept = np.sqrt(np.diagonal(Spread(points, observables)(test), axis1=1, axis2=2))
    sample = np.std(observables, axis=1, ddof=1)
    assert np.median(sample / (0.1 + points)) > 5 and np.all(kept < 5 * (0.1 + test))
    observables[lost] = np.nan
    spread = Spread(points, observables)
    sd = np.sqrt(np.diagonal(spread(test), axis1=1, axis2=2))
    assert sd == pytest.approx(np.repeat(0.1 + test, 2, axis=1), rel=0.45)
    assert spread.dof == int(np.median(k - lost.sum(axis=1))) - 1


def test_the_chance_of_detecting_a_packings_pulse_follows_the_parameters():
    """80 sets of K = 8 packings whose pulse is detected with probability P(u) = 0.9 − 0.6 u (the
    others NaN): the emulated P holds it within 0.1 (one set's share is off by √(P(1 − P)/8) ≤ 0.18;
    the emulator pools the ten or so nearest sets, 0.06 at most, and the Jeffreys estimate pulls
    a share by at most 0.06 towards ½). The records' term R_d log P + R_u log(1 − P) then prefers
    the parameters whose P matches the share of records detected: 3 of 4 at u = 0.25, not 0.75;
    where every packing was detected it adds nothing."""
    from hexdem.calibration.detection import Detection

    rng = np.random.default_rng(4)
    points, observables = correlated_packings(rng, 80, 8, 0.5)
    lost = rng.random((80, 8)) > (0.9 - 0.6 * points)
    observables[lost] = np.nan
    detection = Detection(points, observables)
    test = np.array([[0.1], [0.5], [0.9]])
    assert detection.probability(test) == pytest.approx(0.9 - 0.6 * test[:, 0], abs=0.1)
    log_likelihood = detection.log_likelihood(np.array([[0.25], [0.75]]), detected=3, undetected=1)
    assert log_likelihood[0] > log_likelihood[1] + 0.5
    always = Detection(points, np.nan_to_num(observables))
    assert always.log_likelihood(test, 3, 1) == pytest.approx(0.0) and always.probability(test) == pytest.approx(1.0)


def test_a_simulated_packing_is_detected_as_the_records_sensors_would_detect_it():
    """A packing whose pulse reaches 100 m/s² at sensor 0:1 and 5 m/s² at 0:3 (on y alone): with
    detection levels of 10 m/s² it holds no pulse the records' sensors would see; with 4 m/s² at
    0:3 it does, unless 0:3 measures x alone; without levels every packing is detected."""
    from hexdem.calibration.simulations import detected

    accelerations = np.zeros((2, 50, 2))
    accelerations[0, 10, 0], accelerations[1, 30, 1] = 100.0, 5.0
    problem = Problem(TINY, (Prior("v0", "uniform", 0.2, 0.7),))
    assert detected(problem, accelerations)
    assert not detected(replace(problem, detection_m_s2=(10.0, 10.0)), accelerations)
    assert detected(replace(problem, detection_m_s2=(10.0, 4.0)), accelerations)
    single_axis = replace(problem, detection_m_s2=(10.0, 4.0), axes=((True, True), (True, False)))
    assert not detected(single_axis, accelerations)


def test_a_record_from_a_packing_the_runs_never_took_stays_possible():
    """Every parameter set runs on the same K packings, so K = 2 packings of m = 4 observables
    deviate in one direction only, whatever the number of sets: pooled as it is, their correlation
    is singular, and a record from another packing, deviating elsewhere, is all but impossible
    (the paper protocol's quick workflow: χ² of 600 to 14,000 for 7 observables at the truth).
    Shrunk, R ⪰ λ I with λ = w/(ν + w), w = max(m + 1 − ν, 1), so that Σ_K = D R D (D the emulated
    standard deviations) bounds every record's χ² = rᵀ Σ_K⁻¹ r by Σ_j (r_j / D_j)² / λ."""
    rng = np.random.default_rng(11)
    n, k, m = 40, 2, 4
    points = inference.design(1, n, seed=12)
    shared = rng.standard_normal((k, m))
    observables = points[:, None, :] + (0.1 + points)[:, None, :] * shared[None]
    spread = Spread(points, observables)
    weight = max(m + 1 - (k - 1), 1)
    floor = weight / (k - 1 + weight)
    assert np.linalg.eigvalsh(spread.correlation).min() >= floor - 1e-12
    covariance = spread(np.array([[0.5]]))[0]
    fresh = 0.6 * rng.standard_normal((2000, m))
    chi2 = np.einsum("ri,ri->r", fresh, np.linalg.solve(covariance, fresh.T).T)
    assert np.all(chi2 <= np.sum((fresh / np.sqrt(np.diag(covariance))) ** 2, axis=1) / floor * (1 + 1e-9))


DISORDERED = {"edge_beads": 4, "sensors": ["0:1", "0:3"]}
DISORDERED_TOML = 'edge_beads = 4\nsensors = ["0:1", "0:3"]\n'


@pytest.fixture(scope="module")
def packings(tmp_path_factory):
    """Packing 0 of the 4-per-edge hexagon at σ = 6 tol and 3 tol (seed 0), settled."""
    root = tmp_path_factory.mktemp("packings")
    config = RunConfig.from_dict(DISORDERED)
    model, preparation = build_model(config), preparation_of(config)
    return {
        sigma: settled_packing(model, preparation, sigma, 0, 0, root)[0] for sigma in (TRUE_SIGMA_M, TRUE_SIGMA_M / 2)
    }


def test_the_disorder_prior_sets_the_standard_deviation_of_the_diameters(packings):
    """37 diameters drawn from N(d, σ): their sample sd is σ within 4 σ/√(2 (n − 1)), their mean
    d within 4 σ/√n."""
    diameters = packings[TRUE_SIGMA_M].diameters_m
    n = len(diameters)
    assert np.std(diameters, ddof=1) == pytest.approx(TRUE_SIGMA_M, abs=4 * TRUE_SIGMA_M / np.sqrt(2 * (n - 1)))
    assert np.mean(diameters) == pytest.approx(PAPER_DIAMETER_M, abs=4 * TRUE_SIGMA_M / np.sqrt(n))


def test_neighbouring_sigma_scale_the_same_deviates(packings):
    d = PAPER_DIAMETER_M
    z6 = (packings[TRUE_SIGMA_M].diameters_m - d) / TRUE_SIGMA_M
    z3 = (packings[TRUE_SIGMA_M / 2].diameters_m - d) / (TRUE_SIGMA_M / 2)
    assert z3 == pytest.approx(z6, abs=1e-9)
    assert not np.allclose(packings[TRUE_SIGMA_M].positions_m, packings[TRUE_SIGMA_M / 2].positions_m)


def test_a_settled_packing_is_prepared_once_for_every_impact_on_it(tmp_path):
    """Parameter sets that differ in restitution and v0 alone strike one settled packing; another
    σ or another packing k is prepared anew."""
    priors = (
        Prior("diameter_sigma_m", "uniform", 0.0, 1.5e-4),
        Prior("restitution", "uniform", 0.8, 0.99),
        Prior("v0", "uniform", 0.2, 0.7),
    )
    problem = Problem(DISORDERED, priors, realizations=2, seed=0)
    folders = lambda: sorted(p.name for p in (tmp_path / "packings").iterdir() if not p.name.startswith("."))
    first = simulate_point(problem, [TRUE_SIGMA_M, 0.9, 0.4], tmp_path / "simulations" / "0000-k0", 0)
    prepared = folders()
    stamp = (tmp_path / "packings" / prepared[0] / "settle" / "log.lammps").stat().st_mtime_ns
    second = simulate_point(problem, [TRUE_SIGMA_M, 0.95, 0.5], tmp_path / "simulations" / "0001-k0", 0)
    assert len(prepared) == 1 and folders() == prepared and first != second
    assert (tmp_path / "packings" / prepared[0] / "settle" / "log.lammps").stat().st_mtime_ns == stamp
    simulate_point(problem, [TRUE_SIGMA_M, 0.9, 0.4], tmp_path / "simulations" / "0000-k1", 1)
    simulate_point(problem, [TRUE_SIGMA_M / 2, 0.9, 0.4], tmp_path / "simulations" / "0002-k0", 0)
    assert len(folders()) == 3


def test_a_calibration_of_the_disorder_runs_on_disordered_records(tmp_path):
    """Three records, each of a packing of its own (seeds 1000-1002), at σ = 6 tol and V0 = 0.43 m/s;
    σ and V0 calibrated on K = 2 packings per parameter set: 45 sets, 90 simulations, at most 2
    packings per σ level. One record's sensor 0:3 shows no pulse and is left out, and the count
    enters the likelihood (``detection``). The two kept tell V0 and σ (their intervals 0.57 and 0.61
    of the priors' when this test was written, where a flat likelihood leaves 1), hold the truths
    to four of their standard deviations, and the fit is stated."""
    config = RunConfig.from_dict(DISORDERED | {"v0": TRUE_V0})
    rows = []
    for r in range(3):
        rows += synthetic_rows(
            config,
            str(r),
            2.0,
            1.5e-3,
            np.random.default_rng(3 + r),
            disorder=(TRUE_SIGMA_M, 1000 + r, 0),
            packings=tmp_path / "truth",
        )
    write_measured(tmp_path / "data.csv", rows)
    (tmp_path / "base.toml").write_text(DISORDERED_TOML)
    out = tmp_path / "out"
    priors = ["--prior", "diameter_sigma_m=uniform(0, 1.5e-4)", "--prior", "v0=uniform(0.2, 0.7)"]
    options = ["--realizations", "2", "--budget", "90", "--out", str(out)]
    code = main(
        ["calibrate", "--config", str(tmp_path / "base.toml"), "--measured", str(tmp_path / "data.csv")]
        + priors
        + options
    )
    assert code == 0
    summary = json.loads((out / "calibration.json").read_text())
    assert summary["simulations"]["runs"] == 90 and summary["simulations"]["realizations"] == 2
    assert len(list((out / "simulations").glob("[0-9]*-k1"))) == 45
    assert len(list((out / "packings").glob("[0-9a-f]*"))) <= 2 * SIGMA_LEVELS
    assert summary["detection"]["records_detected"] == 2 and summary["detection"]["records_undetected"] == 1
    samples = np.loadtxt(out / "posterior.csv", delimiter=",", skiprows=1)
    for j, truth in enumerate((TRUE_SIGMA_M, TRUE_V0)):
        assert abs(np.median(samples[:, j]) - truth) <= 4 * np.std(samples[:, j])
    assert_informed(summary, {"diameter_sigma_m": 0.75, "v0": 0.75}, records=2, observables=3)


def pulse_record(noise: float, rng) -> tuple[Record, float, float]:
    """Two sensors whose velocity is V sin²(π (t − t_s)/T) on [t_s, t_s + T]: peak V, half-maximum
    arrival t_s + T/4; their accelerations sampled at 500 kS/s, with white noise."""
    times = np.arange(600) * 2e-6
    peaks, starts, width = (0.1, 0.05), (300e-6, 700e-6), 80e-6
    channels = []
    for peak, start in zip(peaks, starts):
        phase = np.clip((times - start) / width, 0, 1)
        a = peak * np.pi / width * np.sin(2 * np.pi * phase) * ((phase > 0) & (phase < 1))
        channels.append(np.column_stack([a, np.zeros_like(a)]) + rng.normal(0, noise, (len(times), 2)))
    return (
        Record("0", times, np.array(channels), np.ones((2, 2), bool)),
        np.log(peaks[1]),
        (starts[1] - starts[0]) / 1e-6,
    )


def test_a_record_reduces_to_its_pulses_peaks_and_relative_arrival():
    record, log_peak, arrival = pulse_record(0.0, np.random.default_rng(0))
    observed = reduce_record(record.times, record.accelerations)
    # trapezoids under a sine of angular frequency ω sampled every h fall short by (ω h)²/12 of its integral
    shortfall = (2 * np.pi * 2e-6 / 80e-6) ** 2 / 12
    assert observed[1] == pytest.approx(log_peak - shortfall, abs=0.1 * shortfall)
    assert observed[2] == pytest.approx(arrival, abs=0.05)  # µs, against a 2 µs sampling interval


def test_a_records_model_error_moves_its_observables_as_the_discrepancy_term_says():
    """A record made to differ from the model by the relative errors of the discrepancy term
    (:class:`~hexdem.calibration.nuisance.Discrepancy`): the second sensor's log peak 0.03 higher and its
    arrival 5 % of its 400 µs later; the first sensor, the arrivals' reference, unmoved."""
    record, _, _ = pulse_record(0.0, np.random.default_rng(0))
    before = reduce_record(record.times, record.accelerations)
    moved = model_error_applied(record.times, record.accelerations.transpose(1, 0, 2), [[0.0, 0.0], [0.03, 0.05]])
    after = reduce_record(record.times, moved.transpose(1, 0, 2))
    assert after[:2] - before[:2] == pytest.approx([0.0, 0.03], abs=1e-4)
    assert after[2] - before[2] == pytest.approx(0.05 * 400.0, abs=0.05)  # µs


def test_the_accelerometer_noise_is_measured_channel_by_channel_on_the_quiet_lead_in():
    """Four channels of four noise levels and DC offsets: each channel's own level, blind to the
    others' and to its offset (149 quiet samples: the median absolute deviation's standard error is
    about 10 %)."""
    record, _, _ = pulse_record(1.0, np.random.default_rng(1))
    levels, offsets = np.array([[20.0, 5.0], [40.0, 10.0]]), np.array([[300.0, -50.0], [0.0, 2000.0]])
    noisy = Record(
        "0",
        record.times,
        (record.accelerations - np.random.default_rng(1).normal(0, 1, record.accelerations.shape))
        + levels[:, None, :] * np.random.default_rng(2).standard_normal(record.accelerations.shape)
        + offsets[:, None, :],
        record.axes,
    )
    covariance, measured = noise_covariance(noisy, ["a", "b"], seed=0)
    assert measured == pytest.approx(levels, rel=0.3)
    assert np.all(np.linalg.eigvalsh(covariance) > 0)


def test_a_lead_in_that_is_not_at_rest_is_refused():
    """A record triggered as the pulse began: its lead-in climbs through its first sensor's foot
    (a ramp of 60 m/s² over it, against 5 m/s² of noise), which the offset removal would take for
    the sensor's offset."""
    record, _, _ = pulse_record(5.0, np.random.default_rng(4))
    ramp = np.zeros_like(record.accelerations)
    ramp[0, :, 0] = 60.0 * record.times / 300e-6 * (record.times < 300e-6)
    with pytest.raises(HexdemError, match="not at rest before the pulse .* pre-trigger lead-in"):
        noise_covariance(Record("0", record.times, record.accelerations + ramp, record.axes), ["a", "b"], seed=0)


def test_the_lead_in_of_a_weak_first_pulse_ends_at_its_foot_above_the_noise():
    """A first sensor whose pulse is 12 times its noise (a packing whose pulse took another path
    past it), on a DC offset of 20 m/s²: 10 % of its peak is 1.2 noise standard deviations, which
    the noise crosses at once; the foot is where it first reaches 6 of them, within the pulse's
    rise (from 300 µs, 150 samples in, to its peak 10 samples later), and the noise is measured on
    the lead-in before it."""
    record, _, _ = pulse_record(0.0, np.random.default_rng(0))
    rng = np.random.default_rng(8)
    noise = 0.1 * np.pi / 80e-6 / 12
    weak = record.accelerations.copy()
    weak[0] = weak[0] + noise * rng.standard_normal(weak[0].shape) + 20.0
    weak[1] = 50 * weak[1] + noise * rng.standard_normal(weak[1].shape)
    quiet = lead_in(Record("0", record.times, weak, record.axes), ["a", "b"])
    assert 150 - FOOT_SAMPLES <= quiet <= 160 - FOOT_SAMPLES  # the rise takes 10 samples
    _, levels = noise_covariance(Record("0", record.times, weak, record.axes), ["a", "b"], seed=0)
    assert levels == pytest.approx(noise, rel=0.3)


def test_the_lead_in_ends_where_the_pulse_first_reaches_any_sensor():
    """The pulse reaches the second sensor (at 300 µs) before the first (at 700 µs), as on a
    packing whose pulse went around the first by another path: the lead-in ends at the second's
    foot, and the record is calibrated rather than refused as not at rest before the first's."""
    record, _, _ = pulse_record(1.0, np.random.default_rng(6))
    swapped = Record("0", record.times, record.accelerations[::-1].copy(), record.axes)
    assert 150 - FOOT_SAMPLES <= lead_in(swapped, ["a", "b"]) <= 160 - FOOT_SAMPLES
    _, levels = noise_covariance(swapped, ["a", "b"], seed=0)
    assert levels == pytest.approx(1.0, rel=0.35)


def test_a_pulse_that_rings_through_the_record_is_a_pulse():
    """The sensor next to the impact on a small packing: its pulse rings on to the record's end (a
    fifth of its peak acceleration at 50 kHz), so a median absolute deviation over the whole record
    reads 0.2 of the peak as noise. Its noise is read on the quiet lead-in, 1 m/s², and the record is
    calibrated, not refused as a sensor without a pulse."""
    record, _, _ = pulse_record(1.0, np.random.default_rng(9))
    ringing = record.accelerations.copy()
    peak = 0.1 * np.pi / 80e-6
    after = record.times >= 300e-6
    ringing[0, after, 0] += 0.2 * peak * np.sin(2 * np.pi * 50e3 * (record.times[after] - 300e-6))
    whole = 1.4826 * np.median(np.abs(ringing[0, :, 0] - np.median(ringing[0, :, 0])))
    assert 10 * whole > peak  # what the whole record's deviation would call noise
    _, levels = noise_covariance(Record("0", record.times, ringing, record.axes), ["a", "b"], seed=0)
    assert levels == pytest.approx(1.0, rel=0.35)


def test_a_record_of_noise_alone_is_refused_as_holding_no_pulse():
    rng = np.random.default_rng(10)
    noise = Record("0", np.arange(600) * 2e-6, rng.standard_normal((2, 600, 2)), np.ones((2, 2), bool))
    with pytest.raises(HexdemError, match="no sensor of a, b shows a pulse above the accelerometer's noise"):
        noise_covariance(noise, ["a", "b"], seed=0)


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """A synthetic record of the tiny case at v0 = TRUE_V0: twice finer step, noise, clock offset."""
    folder = tmp_path_factory.mktemp("measured")
    config = RunConfig.from_dict(TINY | {"v0": TRUE_V0})
    write_measured(folder / "data.csv", synthetic_rows(config, "0", 5.0, 2.345e-3, np.random.default_rng(7)))
    (folder / "base.toml").write_text(TINY_TOML)
    return folder


def lines_of(path):
    return path.read_text().splitlines()


def damaged(measured, tmp_path, change) -> str:
    lines = lines_of(measured / "data.csv")
    path = tmp_path / "damaged.csv"
    path.write_text("\n".join(change(lines)) + "\n")
    return str(path)


def test_a_record_whose_sensor_shows_no_pulse_is_left_out_of_several(measured, tmp_path):
    """Two records, the second's sensor 0:3 holding noise alone (its pulse did not reach it): the
    second is left out with a note, the first is calibrated, and the simulations' detection level
    is ten times each sensor's noise measured on the record kept (its noisier axis); a file of the
    second record alone is refused."""
    from hexdem.calibration.study import prepare

    lines = lines_of(measured / "data.csv")
    rng = np.random.default_rng(3)
    second = [
        ",".join(l.split(",")[:2] + [f"{5 * rng.standard_normal():.6g}", f"{5 * rng.standard_normal():.6g}", "1"])
        if l.startswith("0:3,")
        else l.rsplit(",", 1)[0] + ",1"
        for l in lines[1:]
    ]
    (tmp_path / "two.csv").write_text("\n".join(lines + second) + "\n")
    calibration = prepare(TINY, tmp_path / "two.csv", ["v0=uniform(0.2, 0.7)"], 30, seed=0)
    assert calibration.data.record_names == ("0",) and calibration.left_out == ("1",)
    assert "record 1 left out: sensor 0:3 shows no pulse above the accelerometer's noise" in calibration.notes
    noise = np.nanmax(calibration.channel_noise_m_s2[0], axis=1)
    assert calibration.problem.detection_m_s2 == pytest.approx(10 * noise)
    assert noise == pytest.approx(5.0, rel=0.5)  # 56 quiet samples: the seed's draw reads 0:1 at 3.45
    (tmp_path / "bad.csv").write_text("\n".join(lines[:1] + second) + "\n")
    with pytest.raises(HexdemError, match="record 1: sensor 0:3 shows no pulse"):
        prepare(TINY, tmp_path / "bad.csv", ["v0=uniform(0.2, 0.7)"], 30, seed=0)


BAD_INPUT = [
    (["--prior", "v0=uniform(0.2)"], None, "expected KEY=uniform(a, b)"),
    (["--prior", "shape=uniform(0, 1)"], None, "not a numeric key"),
    (["--prior", "edge_beds=uniform(1, 2)"], None, "edge_beds"),
    (["--prior", "restitution=uniform(0.9, 1.2)"], None, "restitution"),
    (["--prior", "diameter_m=uniform(-0.01, 0.02)"], None, "diameter_m"),
    (["--prior", "v0=uniform(0.2, 0.7)", "--budget", "20"], None, "too small"),
    (
        ["--prior", "v0=uniform(0.2, 0.7)"],
        lambda lines: [lines[0]] + [l.replace("0:3,", "0:4,", 1) for l in lines[1:]],
        "not among the configuration's sensors",
    ),
    (
        ["--prior", "v0=uniform(0.2, 0.7)"],
        lambda lines: [l for l in lines if not l.startswith("0:3,")],
        "were not measured",
    ),
    (
        ["--prior", "v0=uniform(0.2, 0.7)"],
        lambda lines: lines[:5] + [lines[5].replace(lines[5].split(",")[2], "nan")] + lines[6:],
        "NaN",
    ),
    (["--prior", "v0=uniform(0.2, 0.7)"], lambda lines: [lines[0], lines[2], lines[1]] + lines[3:], "do not increase"),
    (
        ["--prior", "v0=uniform(0.2, 0.7)"],
        lambda lines: (
            [lines[0]] + [l for l in lines[1:] if float(l.split(",")[1]) < float(lines[1].split(",")[1]) + 2e-4]
        ),
        "pulse",
    ),
    (
        ["--prior", "v0=uniform(0.2, 0.7)"],
        lambda lines: (
            [lines[0]]
            + [
                ",".join(
                    l.split(",")[:2]
                    + [f"{0.3 * ((i * 37) % 11 - 5)}", f"{0.3 * ((i * 53) % 7 - 3)}"]
                    + l.split(",")[4:]
                )
                if l.startswith("0:1,")
                else l
                for i, l in enumerate(lines[1:])
            ]
        ),
        "sensor 0:1 shows no pulse above the accelerometer's noise",
    ),
    (["--prior", "diameter_sigma_m=uniform(-1e-5, 1e-4)"], None, "diameter_sigma_m: the standard deviation"),
    (["--prior", "diameter_sigma_m=normal(5e-5, 2e-5)"], None, "reaches -3e-05 m"),
    (["--prior", "diameter_sigma_m=uniform(0, 0.01)"], None, "would hold a bead of diameter"),
    (["--prior", "diameter_sigma_m=uniform(0, 1e-4)", "--realizations", "1"], None, "at least 2 packings"),
    (["--prior", "diameter_sigma_m=uniform(0, 1e-4)", "--realizations", "2", "--budget", "50"], None, "too small"),
    (
        ["--prior", "v0=uniform(0.2, 0.7)", "--realizations", "2", "--config", "chain.toml"],
        None,
        "disordered packings are prepared on the shapes",
    ),
    (
        ["--prior", "v0=uniform(0.2, 0.7)", "--sensor-gain-sd", "-0.01"],
        None,
        "--sensor-gain-sd -0.01: a relative standard deviation in [0, 0.2]",
    ),
    (
        ["--prior", "v0=uniform(0.2, 0.7)", "--speed-scatter", "0.5"],
        None,
        "--speed-scatter 0.5: a relative standard deviation in [0, 0.2]",
    ),
    (
        ["--prior", "v0=uniform(0.2, 0.7)"],
        lambda lines: [l for l in lines if f",{lines[100].split(',')[1]}," not in l],
        "not sampled at a steady rate",
    ),
    (
        ["--prior", "v0=uniform(0.2, 0.7)"],
        lambda lines: (
            [lines[0]]
            + [
                ",".join(l.split(",")[:2] + ["0.0", "0.0"] + l.split(",")[4:]) if l.startswith("0:3,") else l
                for l in lines[1:]
            ]
        ),
        "sensor 0:3 has no axis that varies",
    ),
]


@pytest.mark.parametrize("options, change, message", BAD_INPUT)
def test_bad_input_is_one_line_before_any_simulation(measured, tmp_path, capsys, options, change, message):
    data = str(measured / "data.csv") if change is None else damaged(measured, tmp_path, change)
    out = tmp_path / "out"
    (tmp_path / "chain.toml").write_text('shape = "chain"\nbeads = 5\nsensors = [1, 3]\n')
    options = [str(tmp_path / option) if option.endswith(".toml") else option for option in options]
    code = main(["calibrate", "--config", str(measured / "base.toml"), "--measured", data, "--out", str(out), *options])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 3 and len(err) == 1 and message in err[0], err
    assert not out.exists()


@pytest.mark.parametrize(
    "content, message",
    [
        (bytes(range(256)) * 8, "is a binary file, not a CSV of measured samples"),
        ("sensor,time,ax\n0:1,0.0,1.5\n".encode("utf-16"), "is a binary file"),
        (
            "sensor,time,ax\n0:1,0.0,1.5 m/s\xb2\n".encode("latin-1"),
            "is not UTF-8 text: a binary file, or a CSV saved in another encoding",
        ),
    ],
    ids=["binary", "utf-16", "latin-1"],
)
def test_a_measured_file_that_is_not_utf8_text_is_one_line(measured, tmp_path, capsys, content, message):
    """A binary file, or a CSV saved as UTF-16 (NUL in every other byte) or Latin-1, given as
    ``--measured``: one line naming the file and what it is, exit 3, nothing written."""
    data, out = tmp_path / "data.bin", tmp_path / "out"
    data.write_bytes(content)
    code = main(
        ["calibrate", "--config", str(measured / "base.toml"), "--measured", str(data), "--out", str(out)]
        + ["--prior", "v0=uniform(0.2, 0.7)"]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 3 and len(err) == 1 and message in err[0] and str(data) in err[0], err
    assert not out.exists()


def test_workers_and_parsl_together_are_a_usage_error(measured, tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(
            [
                "calibrate",
                "--measured",
                str(measured / "data.csv"),
                "--prior",
                "v0=uniform(0.2, 0.7)",
                "--out",
                str(tmp_path / "out"),
                "--workers",
                "2",
                "--parsl",
                "config.py",
            ]
        )
    assert stop.value.code == 2 and "not allowed with argument" in capsys.readouterr().err


def calibrate_arguments(measured, out):
    return [
        "calibrate",
        "--config",
        str(measured / "base.toml"),
        "--measured",
        str(measured / "data.csv"),
        "--prior",
        "v0=uniform(0.2, 0.7)",
        "--budget",
        "30",
        "--seed",
        "3",
        "--out",
        str(out),
    ]


def calibrate_command(measured, out):
    return [sys.executable, "-m", "hexdem", *calibrate_arguments(measured, out)]


def finished_simulations(out):
    folder = out / "simulations"
    return {p.name: p.stat().st_mtime_ns for p in folder.glob("[0-9]*")} if folder.is_dir() else {}


def test_a_calibration_finds_the_truth_and_resumes_after_kill_9_to_the_same_posterior(measured, tmp_path):
    """Through the Python API (``hexdem.calibrate``): the posterior holds the truth, is informed, and
    exports to ArviZ (one variable of dimensions (chain, draw), written to netCDF and read back);
    the command, killed with ``kill -9`` and run again, resumes to the same posterior, byte for byte."""
    import xarray

    import hexdem

    whole = tmp_path / "whole"
    posterior = hexdem.calibrate(
        measured / "data.csv", ["v0=uniform(0.2, 0.7)"], whole, measured / "base.toml", budget=30, seed=3
    )
    samples = np.loadtxt(whole / "posterior.csv", delimiter=",", skiprows=1)
    # one noisy record: its 90 % interval misses the truth one time in ten; four standard deviations, 6e-5 of the time
    assert abs(np.median(samples) - TRUE_V0) <= 4 * np.std(samples)
    assert_informed(posterior.summary, {"v0": 0.2}, records=1, observables=3)
    assert posterior.keys == ("v0",) and np.array_equal(posterior.samples[:, 0], samples)
    assert posterior.intervals["v0"] == tuple(np.quantile(samples, [0.05, 0.95]))
    tree = posterior.to_inference_data()
    tree.to_netcdf(tmp_path / "posterior.nc")
    read = xarray.open_datatree(tmp_path / "posterior.nc")["posterior"]["v0"]
    assert read.dims == ("chain", "draw") and read.shape == (sampler.CHAINS, len(samples) // sampler.CHAINS)
    assert np.array_equal(read.values.ravel(), samples)
    for name in ("calibration.json", "posterior.png", "predictive.png"):
        assert (whole / name).stat().st_size > 0

    killed = tmp_path / "killed"
    process = subprocess.Popen(
        calibrate_command(measured, killed),
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 120
    while len(finished_simulations(killed)) < 8 and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    before = finished_simulations(killed)
    assert 8 <= len(before) < 30 and not (killed / "posterior.csv").exists()
    subprocess.run(calibrate_command(measured, killed), check=True, capture_output=True)
    after = finished_simulations(killed)
    assert len(after) == 30 and all(after[name] == stamp for name, stamp in before.items())
    assert (killed / "posterior.csv").read_bytes() == (whole / "posterior.csv").read_bytes()


def assert_informed(summary: dict, widest: dict, records: int, observables: int) -> None:
    """The data informed the posterior and the fit is stated: each key's 90 % interval at most
    ``widest[key]`` of its prior's (a flat likelihood leaves it at 1), the ``records`` kept, the fit's
    ``dof`` R m − p, its
    ``chi2`` finite and within its χ² law's 99.9 % quantile (at a flat posterior's median, far off
    the truth, a record's χ² runs to hundreds), and the chains converged."""
    for key, ratio in widest.items():
        assert summary["parameters"][key]["width_ratio"] <= ratio, (key, summary["parameters"][key])
    fit = summary["fit"]
    assert summary["data"]["records"] == records and len(summary["data"]["observables"]) == observables
    assert fit["dof"] == records * observables - len(summary["parameters"])
    assert 0 <= fit["chi2"] <= stats.chi2.ppf(0.999, fit["dof"]), fit
    assert summary["convergence"]["converged"], summary["convergence"]


def test_stragglers_restart_beside_the_others_and_the_chain_keeps_its_length(monkeypatch):
    """Walkers flagged as stuck (here the first five, whatever their place) restart beside the others,
    and the kept chain has at least its first length (it grows to hold 50 τ), :data:`~sampler.THIN`
    steps apart, with the moments of the normal N(0.5, 0.05²) it samples."""
    monkeypatch.setattr(sampler, "stragglers", lambda log_probability, dimension: np.arange(sampler.WALKERS) < 5)

    def likelihood(unit):
        return -0.5 * np.sum(((unit - 0.5) / 0.05) ** 2, axis=1)

    samples, chain = sampler.sample_posterior(likelihood, 2, seed=1)
    burn_in, kept = sampler.chain_steps(2)
    assert kept <= chain.steps <= sampler.MOST_KEPT * kept
    assert samples.shape == (sampler.CHAINS * sampler.WALKERS * chain.steps // sampler.THIN, 2)
    assert np.mean(samples, axis=0) == pytest.approx([0.5, 0.5], abs=0.01)
    assert np.std(samples, axis=0) == pytest.approx([0.05, 0.05], rel=0.1)


def test_the_chains_converge_on_one_mode_and_r_hat_sees_chains_held_in_two():
    """On a normal N(0.5, 0.05²) the independent chains agree (R̂ < 1.01, bulk and tail ESS ≥ 400,
    50 τ kept); on two equal modes 0.6 apart and 0.01 wide, where no walker crosses the valley
    (e^-1800 of the modes' density), ensembles whose walkers share the modes in other proportions give
    R̂ above 1.01 and a bulk ESS of some 200 (the walkers, not their steps)."""

    def normal(unit):
        return -0.5 * np.sum(((unit - 0.5) / 0.05) ** 2, axis=1)

    def two_modes(unit):
        return np.logaddexp(*(-0.5 * np.sum(((unit - centre) / 0.01) ** 2, axis=1) for centre in (0.2, 0.8)))

    _, chain = sampler.sample_posterior(normal, 2, seed=2)
    assert chain.converged and chain.problems == [], chain.problems
    assert chain.chains == sampler.CHAINS and len(chain.rhat) == 2 and max(chain.rhat) < sampler.RHAT_LIMIT
    _, chain = sampler.sample_posterior(two_modes, 2, seed=2)
    assert not chain.converged and max(chain.rhat) > sampler.RHAT_LIMIT and min(chain.ess_bulk) < sampler.ESS_MINIMUM
    assert any(problem.startswith("R̂ reaches") for problem in chain.problems)


def test_walkers_stuck_where_the_posterior_has_no_mass_are_found():
    """A two-dimensional Gaussian's walkers have log probabilities within a few units of each other
    (−χ²₂/2: 99.99 % above −9.2); two walkers at −7,000, as stuck walkers sat on a curved ridge, are
    the only ones flagged."""
    rng = np.random.default_rng(0)
    log_probability = -0.5 * rng.chisquare(2, size=(150, 64))
    assert not sampler.stragglers(log_probability, 2).any()
    log_probability[:, [5, 17]] -= 7000.0
    assert np.flatnonzero(sampler.stragglers(log_probability, 2)).tolist() == [5, 17]


def test_the_prior_a_physicist_writes_first_is_accepted(measured):
    """restitution = uniform(0.8, 1.0): every restitution in (0, 1] runs in both engines, so the
    configurations at its ends are built and checked before anything runs, and none is refused."""
    from hexdem.calibration.study import prepare
    from hexdem.experiments.sweep_plan import read_base

    calibration = prepare(
        read_base(str(measured / "base.toml")),
        measured / "data.csv",
        ["restitution=uniform(0.8, 1.0)", "v0=uniform(0.2, 0.7)"],
        None,
        0,
    )
    assert calibration.problem.keys == ["restitution", "v0"]


#: Sensor 0:3 reads 3 % high: a routine accelerometer sensitivity error.
LAB_GAINS = (1.0, 1.03)


@pytest.fixture(scope="module")
def lab_record(tmp_path_factory):
    """The tiny case's record as a lab takes it: sensor 0:3 reads 3 % high, each channel has its
    own noise and DC offset, the accelerometers are single-axis (no ay column), the file is in g,
    and it is sampled at 250 kS/s where the configuration says 500 kS/s; made at twice the
    calibration's time resolution."""
    folder = tmp_path_factory.mktemp("lab")
    config = RunConfig.from_dict(TINY | {"v0": TRUE_V0, "sensor_rate_hz": 250e3})
    rows = synthetic_rows(
        config,
        "0",
        [[2.0, 6.0], [1.0, 4.0]],
        2.345e-3,
        np.random.default_rng(11),
        gains=LAB_GAINS,
        offsets_m_s2=[[40.0, -3.0], [-25.0, 7.0]],
    )
    write_measured(folder / "data.csv", rows, unit="g", single_axis=True)
    (folder / "base.toml").write_text(TINY_TOML)
    return folder


def calibrate_lab(lab_record, out, *options):
    return main(
        [
            "calibrate",
            "--config",
            str(lab_record / "base.toml"),
            "--measured",
            str(lab_record / "data.csv"),
            "--prior",
            "v0=uniform(0.2, 0.7)",
            "--budget",
            "30",
            "--seed",
            "3",
            "--out",
            str(out),
            *options,
        ]
    )


def test_a_record_as_a_lab_takes_it_gives_the_truth_and_the_gain_it_was_read_with(lab_record, tmp_path, capsys):
    """Read in g, single-axis, at its own rate, with the gains and speed scatter modelled: the
    interval holds the truth, the fit holds (no warning), and the record shows sensor 0:3 reading
    high against 0:1 by the 3 % it does."""
    assert calibrate_lab(lab_record, tmp_path / "out", "--acceleration-unit", "g") == 0
    output = capsys.readouterr().out
    assert "sampled at 250 kS/s, not the configuration's 500 kS/s" in output and "warning" not in output
    summary = json.loads((tmp_path / "out" / "calibration.json").read_text())
    v0 = summary["parameters"]["v0"]
    assert v0["q05"] <= TRUE_V0 <= v0["q95"]
    assert summary["fit"]["p_value"] > 0.01 and summary["warnings"] == []
    assert_informed(summary, {"v0": 0.2}, records=1, observables=3)
    assert summary["data"]["axes"] == {"0:1": ["x"], "0:3": ["x"]}
    assert summary["data"]["sampling_rate_hz"] == pytest.approx(250e3)
    assert [level[1] for level in summary["data"]["channel_noise_m_s2"][0].values()] == [None, None]
    gains = summary["instruments"]["gains"]
    assert gains["0:3"]["median"] / gains["0:1"]["median"] == pytest.approx(LAB_GAINS[1], abs=0.01)


@pytest.mark.parametrize(
    "options, said",
    [
        ([], ["the model does not fit the records: chi2 = "]),
        (
            ["--acceleration-unit", "g", "--sensor-gain-sd", "0"],
            [
                "the model does not fit the records: chi2 = ",
                "the records differ from the model by a relative ",
                "with and without the model discrepancy the posterior of v0 differs",
            ],
        ),
        (
            ["--acceleration-unit", "g", "--sensor-gain-sd", "0", "--no-model-discrepancy"],
            ["record(s) 0 (p < 0.01 each)"],
        ),
    ],
    ids=["in g read as m/s2", "a gain left out", "a gain left out, the model taken as exact"],
)
def test_a_record_the_model_cannot_fit_is_a_warning(lab_record, tmp_path, capsys, options, said):
    """The same record read in m/s² (9.8 times too small), or with the gains taken as exact (sensor
    0:3's 3 % against 0:1 has no explanation): the command still ends 0, and says in a line that
    begins ``hexdem: warning:`` that the model does not fit the record (read in m/s², with the
    question whether it is in g); with the gains taken as exact, the discrepancy term does not
    silence it: the fit is checked without the term, which grows past the other errors and moves V0
    off its interval without it, each said; taken as exact, the model does not fit it."""
    assert calibrate_lab(lab_record, tmp_path / "out", *options) == 0
    warnings = [line for line in capsys.readouterr().out.splitlines() if line.startswith("hexdem: warning:")]
    assert all(any(phrase in warning for warning in warnings) for phrase in said), warnings
    if not options:
        assert any("are the records in g? (--acceleration-unit g)" in warning for warning in warnings)
    summary = json.loads((tmp_path / "out" / "calibration.json").read_text())
    assert summary["warnings"] == [warning.removeprefix("hexdem: warning: ") for warning in warnings]


def test_gains_three_times_their_stated_error_are_a_warning_that_the_discrepancy_does_not_silence(tmp_path, capsys):
    """Sensors 0:1 and 0:3 reading 6 % high and 6 % low, three times the default
    ``--sensor-gain-sd 0.02``: their ratio is off by 4.2 of its standard deviations, which the model
    discrepancy term (on by default) could absorb as τ; the fit, checked without it, says the model
    does not fit."""
    config = RunConfig.from_dict(TINY | {"v0": TRUE_V0})
    write_measured(
        tmp_path / "data.csv",
        synthetic_rows(config, "0", 5.0, 2.345e-3, np.random.default_rng(7), gains=(1.06, 0.94)),
    )
    (tmp_path / "base.toml").write_text(TINY_TOML)
    out = tmp_path / "out"
    arguments = ["--measured", str(tmp_path / "data.csv"), "--prior", "v0=uniform(0.2, 0.7)", "--budget", "30"]
    assert main(["calibrate", "--config", str(tmp_path / "base.toml"), *arguments, "--out", str(out)]) == 0
    warnings = [line for line in capsys.readouterr().out.splitlines() if line.startswith("hexdem: warning:")]
    assert any("the model does not fit the records" in warning for warning in warnings), warnings
    assert json.loads((out / "calibration.json").read_text())["fit"]["p_value"] < 0.01


def test_the_guides_measured_example_passes_every_input_check():
    """The example the calibration guide's first command calibrates: two records of the tiny case,
    each holding both sensors on both axes at 500 kS/s with a quiet lead-in."""
    from hexdem.calibration.study import prepare
    from hexdem.experiments.sweep_plan import read_base

    examples = Path(__file__).resolve().parents[1] / "docs" / "guide" / "examples"
    calibration = prepare(
        read_base(str(examples / "calibration-base.toml")),
        examples / "measured.csv",
        ["v0=uniform(0.2, 0.7)", "restitution=uniform(0.8, 1.0)"],
        None,
        0,
    )
    assert calibration.data.record_names == ("1", "2") and calibration.rate_hz == pytest.approx(500e3)
    assert calibration.notes == ()


def test_the_spread_between_packings_is_known_to_a_scale_that_k_packings_leave_open():
    """K packings give the spread's variances K − 1 = ν degrees of freedom: the true over the
    estimated is inverse-gamma of shape ν/2, centred on a mean of 1 (scale (ν − 2)/2), whose quantile
    u is (ν − 2)/χ²_ν at 1 − u; the sampler takes that scale as a coordinate after the parameters,
    then each record's packing scale λ_r, inverse-gamma of mean 1 and shape ν/2 for ν = 4, and the
    discrepancy's last. Below ν = 3 there is no mean: the median is 1."""
    from scipy.stats import chi2

    points = inference.design(1, 20, seed=1)
    observables = points[:, None, :] + np.random.default_rng(2).normal(size=(20, 8, 3))
    spread = Spread(points, observables)
    for u in (0.05, 0.5, 0.95):
        assert spread.scale(np.array([u]))[0] == pytest.approx(5 / chi2.ppf(1 - u, 7), rel=1e-9)
        assert spread.record_scale(np.array([u]))[0] == pytest.approx(
            (RECORD_TAIL_DOF - 2) / chi2.ppf(1 - u, RECORD_TAIL_DOF), rel=1e-9
        )
    assert np.mean(spread.scale(np.linspace(0, 1, 200_001)[1:-1])) == pytest.approx(1.0, rel=0.01)
    assert variance_ratio(0.5, 2) == pytest.approx(1.0) and variance_ratio(0.5, 1) == pytest.approx(1.0)
    data = inference.Data(observables[:2, 0], np.array([np.eye(3) * 1e-4] * 2), ("a", "b", "c"))
    emulator = Emulator(points, observables.mean(axis=1))
    assert inference.Likelihood(data, emulator, spread).dimension == 4
    assert inference.Likelihood(data, emulator, spread, discrepancy=nuisance.Discrepancy(2)).dimension == 5
    assert inference.Likelihood(data, emulator, Spread(points, observables[:, :1])).dimension == 1


def test_the_rank_ecdf_band_holds_calibrated_posteriors_and_sees_narrow_ones():
    """The simultaneous 95 % band of 100 truths' rank ECDF: a conjugate normal posterior (prior
    N(0.5, 0.1²), a measurement of sd 0.03) stays inside it in about 95 of 100 studies (binomial 95 %
    band [89, 99]); one 0.7 times too narrow (its 90 % intervals covering 0.75) leaves it in most, as
    the band's stated power says (0.93, Monte Carlo); TARP's shares, uniform for the calibrated
    posterior, sit inside the same band as often, and the narrow posterior's leave it."""
    from hexdem.calibration import coverage

    assert coverage.central_coverage(1.0) == pytest.approx(0.9)
    assert coverage.central_coverage(0.7) == pytest.approx(0.75, abs=0.005)
    count, draws_each = 100, 200
    band = coverage.ecdf_band(count)
    rng = np.random.default_rng(8)
    variance = 1 / (1 / 0.1**2 + 1 / 0.03**2)
    outside = {1.0: [0, 0], 0.7: [0, 0]}
    for _ in range(100):
        truths = 0.5 + 0.1 * rng.standard_normal((count, 2))
        measured = truths + 0.03 * rng.standard_normal((count, 2))
        centre = variance * (0.5 / 0.1**2 + measured / 0.03**2)
        for scale in outside:
            draws = centre[:, None, :] + scale * np.sqrt(variance) * rng.standard_normal((count, draws_each, 2))
            ranks = coverage.fractional_ranks(draws[:, :, 0], truths[:, 0])
            shares = coverage.tarp(draws, truths, 0.5 + 0.1 * rng.standard_normal((count, 2)))[3]
            outside[scale][0] += coverage.outside_band(ranks, band)
            outside[scale][1] += coverage.outside_band(shares, band)
    assert all(1 <= count_ <= 11 for count_ in outside[1.0]), outside
    assert all(count_ >= 80 for count_ in outside[0.7]), outside
    assert coverage.ecdf_power(count, 0.7) == pytest.approx(0.93, abs=0.05)


def test_lab_faults_shift_the_samples_and_colour_the_noise_as_drawn():
    """The misspecified arm's faults: with no phase, skew or gain the samples are the signal's own;
    half an interval off, a sine sampled 10 times a period reads the sine half an interval later (to
    the cubic spline's error inside its two end samples, 1e-3 of its amplitude); the noise keeps
    each channel's level and its lag-one correlation is the memory drawn (20,000 samples: ±0.02);
    the drift is a ramp."""
    from hexdem.calibration.synthetic import LabFaults

    times = np.arange(400) * 1e-6
    signal = np.sin(2 * np.pi * times / 10e-6)[:, None, None] * np.ones((1, 2, 2))
    none = LabFaults(0.0, np.zeros(2), np.ones((2, 2)), 0.0, np.zeros((2, 2)))
    assert none.resampled(times, signal, 1e-6) == pytest.approx(signal)
    half = LabFaults(0.5, np.zeros(2), np.full((2, 2), 1.1), 0.7, np.full((2, 2), 3.0))
    later = np.sin(2 * np.pi * (times + 0.5e-6) / 10e-6)[2:-2, None, None] * 1.1
    assert half.resampled(times, signal, 1e-6)[2:-2] == pytest.approx(np.broadcast_to(later, (396, 2, 2)), abs=2e-3)
    recorded = half.recorded(np.zeros((20_000, 2, 2)), np.full((2, 2), 2.0), np.random.default_rng(5))
    noise = recorded - np.linspace(0, 1, 20_000)[:, None, None] * 3.0
    assert np.std(noise, axis=0) == pytest.approx(2.0, rel=0.1)
    lag = np.mean(noise[1:] * noise[:-1], axis=0) / np.var(noise, axis=0)
    assert lag == pytest.approx(0.7, abs=0.02)


def test_a_spread_where_most_packings_agree_exactly_is_not_zero():
    """Five of 8 packings reach a sensor by the same contacts (the same arrival to the last digit), 3
    by others 10, 20 and 40 µs later: the median absolute deviation is 0, and the robust scale falls
    back to the mean absolute deviation's, √(π k/(2 (k − 1))) × 70/8 µs = 11.7 µs; a set of one valid
    packing, or of packings that all agree, has none."""
    from hexdem.calibration.spread import robust_sd

    values = np.array([[[150.0]] * 5 + [[160.0], [170.0], [190.0]]]).reshape(1, 8, 1)
    scale = robust_sd(values, np.ones((1, 8), bool))
    assert scale[0, 0] == pytest.approx(np.sqrt(np.pi * 8 / 14) * 70 / 8)
    assert robust_sd(values, np.eye(1, 8, dtype=bool))[0, 0] == 0.0
    assert robust_sd(np.full((1, 8, 1), 3.0), np.ones((1, 8), bool))[0, 0] == 0.0
