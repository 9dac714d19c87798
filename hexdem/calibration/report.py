"""What a calibration reports: the posterior's samples, its summary, and what the data cannot tell.

``posterior.csv`` holds one column per prior key and one row per posterior sample (unweighted:
emcee's chain, thinned). ``calibration.json`` holds, per key, its prior, the posterior's mean,
median, 5 % and 95 % quantiles and ``width_ratio``, the posterior's 90 % interval over the
prior's; the posterior's correlations; and ``identifiability``, sentences that say where the data
cannot tell two parameters apart (an absolute correlation of :data:`TRADE_OFF_CORRELATION` or more: they trade off, and only a
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


def summarize(priors, samples) -> dict:
    """Per key: prior, mean, median, q05, q95, width_ratio; with correlations and identifiability."""
    keys = [prior.key for prior in priors]
    parameters = {}
    for j, prior in enumerate(priors):
        q05, median, q95 = np.quantile(samples[:, j], QUANTILES)
        p05, p95 = prior.from_unit([QUANTILES[0], QUANTILES[2]])
        parameters[prior.key] = {"prior": prior.as_dict(), "mean": float(np.mean(samples[:, j])),
                                 "median": float(median), "q05": float(q05), "q95": float(q95),
                                 "width_ratio": float((q95 - q05) / (p95 - p05))}
    correlations = np.corrcoef(samples, rowvar=False) if len(keys) > 1 else np.ones((1, 1))
    return {"parameters": parameters,
            "correlations": {a: {b: float(correlations[i, j]) for j, b in enumerate(keys)} for i, a in enumerate(keys)},
            "identifiability": identifiability(keys, parameters, np.atleast_2d(correlations))}


def identifiability(keys, parameters: dict, correlations) -> list[str]:
    """Sentences on what the data cannot tell (see the module's docstring); empty if nothing."""
    notes = []
    for i, a in enumerate(keys):
        for j in range(i + 1, len(keys)):
            rho = correlations[i, j]
            if abs(rho) >= TRADE_OFF_CORRELATION:
                notes.append(f"{a} and {keys[j]} trade off (posterior correlation {rho:+.2f}): the data measure a "
                             "combination of them, not each alone; their intervals are not independent")
    for key in keys:
        ratio = parameters[key]["width_ratio"]
        if ratio >= UNCONSTRAINED_RATIO:
            notes.append(f"the data barely constrain {key}: its 90 % interval is {ratio:.0%} of the prior's")
    return notes


def write_posterior(path, priors, samples) -> None:
    write_csv_columns(path, [prior.key for prior in priors], [samples[:, j] for j in range(samples.shape[1])])
