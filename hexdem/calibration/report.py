"""What a calibration reports: the posterior's samples, its summary, and what the data cannot tell.

``posterior.csv`` holds one column per prior key and one row per posterior sample (unweighted:
emcee's chain, thinned). ``calibration.json`` holds, per key, its prior, the posterior's mean,
median, 5 % and 95 % quantiles and ``width_ratio``, the posterior's 90 % interval over the
prior's; the posterior's correlations; ``directions``, the combinations of the keys that the data
measure (:func:`directions`); and ``identifiability``, sentences that say where the data
cannot tell two parameters apart (an absolute correlation of :data:`TRADE_OFF_CORRELATION` or more: they trade off, and
only a
combination of them is measured) or barely constrain one (``width_ratio`` ≥
:data:`UNCONSTRAINED_RATIO`), so that no precision is quoted that the data do not hold.
"""

from __future__ import annotations

import numpy as np

from hexdem.common.io import write_csv_columns

#: The absolute posterior correlation from which two parameters are reported as trading off.
TRADE_OFF_CORRELATION = 0.9
#: Posterior 90 % width over the prior's from which a parameter is reported as barely constrained.
UNCONSTRAINED_RATIO = 0.8
QUANTILES = (0.05, 0.5, 0.95)
#: A key's share of a measured direction from which the direction is said to involve it.
COMBINATION_SHARE = 0.3


def summarize(priors, samples) -> dict:
    """Per key: prior, mean, median, q05, q95, width_ratio; with correlations and identifiability."""
    keys = [prior.key for prior in priors]
    parameters = {}
    for j, prior in enumerate(priors):
        q05, median, q95 = np.quantile(samples[:, j], QUANTILES)
        p05, p95 = prior.from_unit([QUANTILES[0], QUANTILES[2]])
        parameters[prior.key] = {
            "prior": prior.as_dict(),
            "mean": float(np.mean(samples[:, j])),
            "median": float(median),
            "q05": float(q05),
            "q95": float(q95),
            "width_ratio": float((q95 - q05) / (p95 - p05)),
        }
    correlations = np.corrcoef(samples, rowvar=False) if len(keys) > 1 else np.ones((1, 1))
    unit = np.column_stack([prior.to_unit(samples[:, j]) for j, prior in enumerate(priors)])
    found = directions(keys, unit)
    return {
        "parameters": parameters,
        "correlations": {a: {b: float(correlations[i, j]) for j, b in enumerate(keys)} for i, a in enumerate(keys)},
        "directions": found,
        "identifiability": identifiability(keys, parameters, np.atleast_2d(correlations))
        + direction_notes(keys, found),
    }


def directions(keys, unit_samples) -> list[dict]:
    """The directions of the priors' unit cube that the data measure, best measured first: the
    eigenvectors of the posterior's covariance over the prior's (I/12 in the unit cube, whatever
    the priors), each with ``combination`` (its components per key, the largest positive) and
    ``sd_over_prior``, the posterior's standard deviation along it over the prior's. Unlike
    pairwise correlations, it sees a combination of any number of keys, and a key held by its
    prior's box keeps a ratio near 1."""
    covariance = np.atleast_2d(np.cov(unit_samples, rowvar=False)) * 12.0
    values, vectors = np.linalg.eigh(covariance)
    found = []
    for value, vector in zip(values, vectors.T):
        vector = vector * np.sign(vector[np.argmax(np.abs(vector))])
        found.append(
            {
                "combination": {key: float(c) for key, c in zip(keys, vector)},
                "sd_over_prior": float(np.sqrt(max(value, 0.0))),
            }
        )
    return found


def direction_notes(keys, found: list[dict]) -> list[str]:
    """Sentences on the measured combinations of several keys (:func:`directions`), and on the keys
    that no measured direction involves (left at their prior)."""
    notes, measured = [], [d for d in found if d["sd_over_prior"] < UNCONSTRAINED_RATIO]
    for direction in measured:
        parts = [(key, c) for key, c in direction["combination"].items() if abs(c) >= COMBINATION_SHARE]
        if len(parts) > 1:
            text = " ".join(f"{'-' if c < 0 else '+'} {abs(c):.2f} {key}" for key, c in parts).lstrip("+ ")
            notes.append(
                f"the data measure the combination {text} (in the priors' unit scale) to "
                f"{direction['sd_over_prior']:.0%} of its prior's spread, rather than each key alone"
            )
    for key in keys:
        if all(abs(d["combination"][key]) < COMBINATION_SHARE for d in measured):
            notes.append(f"the data leave {key} at its prior: no direction they measure involves it")
    return notes


def identifiability(keys, parameters: dict, correlations) -> list[str]:
    """Sentences on what the data cannot tell (see the module's docstring); empty if nothing."""
    notes = []
    for i, a in enumerate(keys):
        for j in range(i + 1, len(keys)):
            rho = correlations[i, j]
            if abs(rho) >= TRADE_OFF_CORRELATION:
                notes.append(
                    f"{a} and {keys[j]} trade off (posterior correlation {rho:+.2f}): the data measure a "
                    "combination of them, not each alone; their intervals are not independent"
                )
    for key in keys:
        ratio = parameters[key]["width_ratio"]
        if ratio >= UNCONSTRAINED_RATIO:
            notes.append(f"the data barely constrain {key}: its 90 % interval is {ratio:.0%} of the prior's")
    return notes


def write_posterior(path, priors, samples) -> None:
    write_csv_columns(path, [prior.key for prior in priors], [samples[:, j] for j in range(samples.shape[1])])
