"""What a calibration says about itself: whether the model fits the records, whether its chain
mixed, how far its emulator is off, where its priors hold the posterior, and each sensor's gain.

**The fit** is checked with the model taken as exact: the discrepancy term τ left out
(:meth:`~hexdem.calibration.inference.Likelihood.without_discrepancy`), for τ grows to absorb
whatever misfit it is asked about (sensors' gains off by 6 % passed a check that kept it). Two
measures, each with the full covariance that the likelihood gives the records
(:meth:`~hexdem.calibration.inference.Likelihood.misfit`: the noise of each record, the packings'
spread, the striker's speed scatter, and the errors common to every record, the emulator's, the
time step's and the sensors' gains): the records' χ² at u*, the posterior draw where the exact
model's likelihood is highest (not the coordinates' medians, which on a posterior of several
modes or a curved ridge lie where it has no mass), with R m − p degrees of freedom together (R
records of m observables, p parameters) and m for each record alone, exact for a model linear in
the parameters near u*; and the posterior predictive p-value
of the χ² discrepancy (Gelman, Meng & Stern 1996), P(T(y_rep, θ) ≥ T(y, θ) | y) over the
posterior's draws θ, where a replicated record set y_rep of the exact model at θ makes T(y_rep, θ)
a χ² of R m degrees of freedom, so that the p-value is the mean of its survival function at
T(y, θ). Either p-value below :data:`~hexdem.calibration.assessment.MISFIT_P` is a warning naming the
records that do not fit: the model, the instruments or the configuration differ from what the
records measured, and the intervals then say too little.
"""

from __future__ import annotations

import numpy as np

from hexdem.calibration.observables import STANDARD_GRAVITY_M_S2

#: Posterior draws at which the posterior predictive p-value is taken.
PREDICTIVE_CHECK_DRAWS = 200
#: How many times wider one posterior's 90 % interval may be than another's before they disagree.
DISAGREEMENT_WIDTH_RATIO = 2.0


def goodness_of_fit(likelihood, states, parameters: int, rng, draws: int = PREDICTIVE_CHECK_DRAWS) -> dict:
    """``fit`` of ``calibration.json`` (see the module docstring): with the model taken as exact
    (:meth:`~hexdem.calibration.inference.Likelihood.without_discrepancy`), ``chi2``, ``dof`` and
    ``p_value`` of the records together at the most likely of the sampler's ``states``, and
    ``predictive_p_value``, the posterior predictive p-value over ``draws`` of them; ``records``,
    each record's ``record``, ``chi2``, ``p_value`` and ``predictive_p_value``."""
    from scipy.stats import chi2 as chi_squared

    exact = likelihood.without_discrepancy()
    states = np.asarray(states, float)[:, : exact.dimension]
    data = likelihood.data
    together, alone = exact.misfit(states[int(np.argmax(exact(states)))])
    chosen = states[rng.choice(len(states), min(draws, len(states)), replace=False)]
    realized = [exact.misfit(unit) for unit in chosen]
    count, size = data.records.shape
    dof = max(count * size - parameters, 1)
    names = data.record_names or tuple(str(r) for r in range(count))
    each = np.array([record for _, record in realized])
    return {
        "method": (
            "the model taken as exact (no discrepancy term): chi-square with the likelihood's covariance at "
            "the most likely posterior draw, and the posterior predictive p-value of the chi-square discrepancy"
        ),
        "chi2": together,
        "dof": dof,
        "p_value": float(chi_squared.sf(together, dof)),
        "predictive_p_value": float(np.mean(chi_squared.sf([total for total, _ in realized], count * size))),
        "records": [
            {
                "record": name,
                "chi2": value,
                "p_value": float(chi_squared.sf(value, size)),
                "predictive_p_value": float(np.mean(chi_squared.sf(each[:, r], size))),
            }
            for r, (name, value) in enumerate(zip(names, alone))
        ],
    }


def misfit_records(fit: dict, threshold: float) -> list[str]:
    """The records of ``fit`` (:func:`goodness_of_fit`) whose p-value, at the median or predictive,
    lies below ``threshold``."""
    return [entry["record"] for entry in fit["records"] if misfit_together(entry, threshold)]


def misfit_together(fit: dict, threshold: float) -> bool:
    """Whether ``fit`` (:func:`goodness_of_fit`'s records together, or one record's entry) does not fit:
    either p-value below ``threshold``."""
    return min(fit["p_value"], fit["predictive_p_value"]) < threshold


def predictive_residuals(likelihood, draws, rng) -> np.ndarray:
    """Each record's observables less the median of its own posterior predictive distribution, in
    units of that distribution's standard deviation (R, m): at the posterior's ``draws`` (k, d) of
    the sampler's unit cube, N(μ, Σ_r + C + λ_r Σ_K + V) with the record's own noise Σ_r and
    packing scale λ_r (:meth:`~hexdem.calibration.inference.Likelihood.record_moments`), so that a
    record whose packing took a weak path stands as far off as its χ² says, and no farther."""
    data = likelihood.data
    mean, common, owns = likelihood.record_moments(draws)
    residuals = []
    for record, noise, own in zip(data.records, data.covariances, owns):
        predicted = gaussian_draws(rng, mean, noise + common + own)
        residuals.append((record - np.median(predicted, axis=0)) / np.std(predicted, axis=0))
    return np.array(residuals)


def gaussian_draws(rng, mean, covariance) -> np.ndarray:
    """One draw (k, m) of each N(``mean[i]``, ``covariance[i]``), ``mean`` (k, m) and ``covariance`` (k, m, m)."""
    lower = np.linalg.cholesky(covariance)
    return mean + np.einsum("kij,kj->ki", lower, rng.standard_normal(mean.shape))


def in_g_hint(records, simulated, sensors: int) -> str:
    """A sentence for records whose peak speeds lie below every simulation's by about standard
    gravity's factor (records in g read as m/s²), else an empty one: ``records`` (R, m) and the
    simulations' ``simulated`` (n, K, m) observables, the first ``sensors`` of them log peaks."""
    measured = float(np.mean(records[:, :sensors]))
    lowest, highest = float(np.nanmin(simulated[..., :sensors])), float(np.nanmax(simulated[..., :sensors]))
    scaled = measured + np.log(STANDARD_GRAVITY_M_S2)
    if measured < lowest - np.log(2.0) and lowest - 1.0 <= scaled <= highest + 1.0:
        return (
            f" The measured peak speeds lie {np.exp(lowest - measured):.3g} times or more below every "
            "simulation's: are the records in g? (--acceleration-unit g)"
        )
    return ""


def piled_against_bounds(priors, unit_samples, share: float, zone: float) -> list[str]:
    """Sentences for each bounded prior (uniform, loguniform) whose posterior puts more than ``share``
    of its samples within ``zone`` of a bound in the unit cube (where the prior puts ``zone``)."""
    notes = []
    for j, prior in enumerate(priors):
        if prior.kind == "normal":
            continue
        for side, mass, bound in (
            ("lower", np.mean(unit_samples[:, j] < zone), prior.a),
            ("upper", np.mean(unit_samples[:, j] > 1 - zone), prior.b),
        ):
            if mass > share:
                notes.append(
                    f"the posterior of {prior.key} piles against its prior's {side} bound {bound:g} "
                    f"({mass:.0%} of it within {zone:.0%} of the prior's range from it): the records may "
                    "want a value beyond it; widen the prior"
                )
    return notes


def disagreeing_keys(keys, with_discrepancy, without) -> list[tuple[str, str]]:
    """(key, what differs) for each of ``keys`` whose posterior samples ``with_discrepancy`` and
    ``without`` it (n, p) disagree: 90 % intervals that do not overlap, or one more than
    :data:`DISAGREEMENT_WIDTH_RATIO` times as wide as the other. Records that the model fits leave τ
    below their noise, and both posteriors alike."""
    found = []
    for j, key in enumerate(keys):
        (a, b), (c, d) = np.quantile(with_discrepancy[:, j], [0.05, 0.95]), np.quantile(without[:, j], [0.05, 0.95])
        ratio = (b - a) / max(d - c, np.finfo(float).tiny)
        if b < c or d < a or not 1 / DISAGREEMENT_WIDTH_RATIO <= ratio <= DISAGREEMENT_WIDTH_RATIO:
            found.append((key, f"90 % interval [{a:.4g}, {b:.4g}] with it, [{c:.4g}, {d:.4g}] without"))
    return found


def quantile_summary(values) -> dict:
    """``q05``, ``median`` and ``q95`` of ``values``, as ``calibration.json`` gives a quantity's posterior."""
    q05, median, q95 = map(float, np.quantile(values, [0.05, 0.5, 0.95]))
    return {"q05": q05, "median": median, "q95": q95}


def gain_estimates(likelihood, unit_samples, sensors, rng) -> dict:
    """Each sensor's gain given the records: per sensor its ``median``, ``q05`` and ``q95``, from
    the conditional normal of its log gain (:meth:`~hexdem.calibration.inference.Likelihood.log_gains`)
    at each of ``unit_samples``, mixed."""
    centre, variance = likelihood.log_gains(unit_samples)
    draws = np.exp(centre + np.sqrt(np.maximum(variance, 0.0)) * rng.standard_normal(centre.shape))
    return {str(sensor): quantile_summary(draws[:, s]) for s, sensor in enumerate(sensors)}


def emulator_error(emulator, names, noise_sd) -> dict:
    """The emulator's leave-one-out error per observable (``names``): its root mean square, and that
    over the records' mean noise standard deviation ``noise_sd`` (m,)."""
    rms = np.sqrt(np.mean(emulator.leave_one_out() ** 2, axis=0))
    return {
        "leave_one_out_rms": dict(zip(names, map(float, rms))),
        "leave_one_out_over_noise": dict(zip(names, map(float, rms / noise_sd))),
    }
