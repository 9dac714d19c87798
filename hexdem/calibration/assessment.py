"""What a calibration says of its own result: whether the model fits the records, whether the
chains converged, what the model discrepancy term carries, and the warnings that say so.

Each check is one of :mod:`~hexdem.calibration.diagnostics`; this module applies them to the final
fit (:func:`assess`) with the thresholds of ``hexdem calibrate``, so that a misfit is never silent:
the fit is judged with the model taken as exact, τ's size against the other errors, and the
intervals with and without τ against each other.
"""

from __future__ import annotations

import numpy as np

from hexdem.calibration import diagnostics
from hexdem.calibration.inference import Data, Fit
from hexdem.calibration.nuisance import Discrepancy, Instruments
from hexdem.calibration.priors import to_parameters
from hexdem.calibration.sampler import sample_posterior

#: p-value below which a record, or the records together, do not fit the model.
MISFIT_P = 0.01
#: A share of the posterior's samples within :data:`BOUND_ZONE` of a bound of its prior (in the
#: prior's unit cube, where the prior puts BOUND_ZONE there) from which the posterior piles against it.
PILED_SHARE = 0.2
BOUND_ZONE = 0.02
#: The model discrepancy's relative size (its 5 % quantile) from which the records are said to differ
#: from the model: half a per cent, above what the time step and the emulator leave.
DISCREPANCY_WARNING = 0.005
#: Posterior samples at which each sensor's gain is estimated.
GAIN_DRAWS = 256


def assess(fit: Fit, problem, data: Data, instruments: Instruments, discrepancy: Discrepancy | None, seed: int) -> dict:
    """``calibration.json``'s ``fit``, ``convergence``, ``emulator``, ``instruments`` (with each
    sensor's gain), the spread's scales, ``detection`` (the records detected and left out, and the
    posterior of the chance P that a packing's pulse is detected, :mod:`~hexdem.calibration.detection`),
    ``model_discrepancy`` and ``warnings`` of the final ``fit``
    of ``problem`` (:class:`~hexdem.calibration.simulations.Problem`) to the records ``data``."""
    rng = np.random.default_rng(seed + 1)
    summary = {}
    summary["fit"] = diagnostics.goodness_of_fit(fit.likelihood, fit.states, len(problem.priors), rng)
    summary["convergence"] = fit.chain.as_dict()
    noise_sd = np.sqrt(np.mean(np.diagonal(data.covariances, axis1=1, axis2=2), axis=0))
    summary["emulator"] = diagnostics.emulator_error(fit.emulator, data.names, noise_sd)
    summary["instruments"] = {"sensor_gain_sd": instruments.gain_sd, "speed_scatter": instruments.speed_scatter}
    if fit.spread_scales is not None:
        summary["spread_scale"] = diagnostics.quantile_summary(fit.spread_scales)
        summary["record_spread_scales"] = [
            {"record": name} | diagnostics.quantile_summary(scales)
            for name, scales in zip(data.record_names, fit.record_scales.T)
        ]
    if fit.likelihood.detection is not None:
        summary["detection"] = {
            "records_detected": len(data.records),
            "records_undetected": data.undetected,
            "probability": diagnostics.quantile_summary(fit.likelihood.detection.probability(fit.samples)),
        }
    if instruments.gain_sd > 0:
        chosen = fit.states[rng.choice(len(fit.states), min(GAIN_DRAWS, len(fit.states)), replace=False)]
        summary["instruments"]["gains"] = diagnostics.gain_estimates(fit.likelihood, chosen, problem.sensors, rng)
    warnings = []
    bad = diagnostics.misfit_records(summary["fit"], MISFIT_P)
    if diagnostics.misfit_together(summary["fit"], MISFIT_P) or bad:
        named = f"; record(s) {', '.join(bad)} (p < {MISFIT_P:g} each)" if bad else ""
        warnings.append(
            f"the model does not fit the records: chi2 = {summary['fit']['chi2']:.4g} for "
            f"{summary['fit']['dof']} degrees of freedom (p = {summary['fit']['p_value']:.2g}, posterior "
            f"predictive p = {summary['fit']['predictive_p_value']:.2g}){named}; the "
            "intervals say too little: check the records' units, gains and sensors, the configuration "
            "and the priors (predictive.png)."
            + diagnostics.in_g_hint(data.records, fit.observables, len(problem.sensors))
        )
    if fit.discrepancy_sizes is not None:
        summary["model_discrepancy"], said = _discrepancy_checks(fit, problem, data, discrepancy, seed)
        warnings += said
    warnings += diagnostics.piled_against_bounds(problem.priors, fit.samples, PILED_SHARE, BOUND_ZONE)
    if not fit.chain.converged:
        warnings.append(
            f"the sampler's {fit.chain.chains} independent chains did not converge: "
            + "; ".join(fit.chain.problems)
            + ": the intervals are uncertain"
        )
    summary["warnings"] = warnings
    return summary


def _discrepancy_checks(fit: Fit, problem, data: Data, discrepancy: Discrepancy, seed: int) -> tuple[dict, list[str]]:
    """``model_discrepancy`` of ``calibration.json`` and its warnings: τ's posterior (median, 5 % and
    95 % quantiles), ``over_errors``, the error of each observable at τ's median over the standard
    deviation of all the others that the likelihood gives it at the posterior median (the record's
    noise, the packings' spread, the speed scatter, the emulator's, the time step's and the gains'),
    and ``without``, each key's interval with the model taken as exact (its posterior sampled again
    without τ). A warning when τ's 5 % quantile passes :data:`DISCREPANCY_WARNING` or its error passes
    the others on an observable (τ then carries the fit, not the errors one can name), and one when the
    intervals with and without it disagree (:func:`~hexdem.calibration.diagnostics.disagreeing_keys`):
    the discrepancy then carries the posterior, and what it only widens is not corrected."""
    size = diagnostics.quantile_summary(fit.discrepancy_sizes)
    exact = fit.likelihood.without_discrepancy()
    mean, common, own = exact.moments(np.median(fit.states[:, : exact.dimension], axis=0))
    others = np.diagonal(np.mean(data.covariances, axis=0) + common[0] + own[0])
    over_errors = size["median"] * np.sqrt(discrepancy.weights(mean)[0] / others)
    states, _ = sample_posterior(exact, exact.dimension, seed + 2, chains=1)
    without = to_parameters(problem.priors, states[:, : len(problem.priors)])
    with_it = to_parameters(problem.priors, fit.samples)
    record = discrepancy.as_dict() | size
    record["over_errors"] = dict(zip(data.names, map(float, over_errors)))
    record["without"] = {key: diagnostics.quantile_summary(without[:, j]) for j, key in enumerate(problem.keys)}
    warnings = []
    if size["q05"] > DISCREPANCY_WARNING or np.max(over_errors) > 1:
        warnings.append(
            f"the records differ from the model by a relative {size['median']:.2g} (90 % interval "
            f"[{size['q05']:.2g}, {size['q95']:.2g}]; {np.max(over_errors):.2g} times the other errors of "
            f"{data.names[int(np.argmax(over_errors))]}) that neither their noise nor the instruments "
            "explain: the model misses something the records hold (dissipation, friction, the walls, the "
            "packing, the sensors' gains?); the intervals allow for it, and are wider for it"
        )
    for key, described in diagnostics.disagreeing_keys(problem.keys, with_it, without):
        warnings.append(
            f"with and without the model discrepancy the posterior of {key} differs ({described}): the "
            "discrepancy term carries the fit; the records hold a misfit that it only widens the intervals for"
        )
    return record, warnings
