"""The calibration's figures: the posterior's corner plot and the posterior predictive check.

``posterior.png``: each parameter's marginal histogram on the diagonal, every pair's joint
histogram below it, zoomed to where the posterior lies (its 0.1 % to 99.9 % quantiles, widened by
a tenth), with the 5 %, 50 % and 95 % quantiles marked and each prior stated above its column;
axes named with their units (:func:`axis_label`).
``predictive.png``: above, in the style of the paper's Fig. 9, each sensor's measured peak speed
and relative arrival against its distance from the struck bead (mean of the records, error bars
one standard deviation of their noise, dots for single records) beside the posterior predictive
90 % band: the emulated observables at the posterior's samples, with every term of the likelihood
added (noise, the packings' spread, the instruments, the common errors). Below, each record's
residual from the predictive median in units of the predictive standard deviation, the ±1 and ±2
bands shaded; records that do not fit the model (:mod:`~hexdem.calibration.diagnostics`) marked.
"""

from __future__ import annotations

import numpy as np

from hexdem.analysis.plotting import plain_log_ticks, save, subplots
from hexdem.calibration.observables import ARRIVAL_UNIT_S

#: Axis labels of the keys a calibration usually has: (label, factor from the key's unit to the label's).
LABELS = {
    "v0": ("V₀ [m/s]", 1.0),
    "restitution": ("e", 1.0),
    "wall_restitution": ("e (walls)", 1.0),
    "diameter_sigma_m": ("σ [µm]", 1e6),
    "friction": ("μ", 1.0),
    "wall_friction": ("μ (walls)", 1.0),
}
#: A key's unit from its name's suffix, for the keys :data:`LABELS` does not name.
SUFFIX_UNITS = {"_m": "m", "_pa": "Pa", "_hz": "Hz", "_s": "s", "_kg_m3": "kg/m³", "_m_s": "m/s", "_deg": "°"}


def axis_label(key: str) -> tuple[str, float]:
    """(the axis label of the calibrated ``key`` with its unit, the factor from its values to the axis's)."""
    if key in LABELS:
        return LABELS[key]
    unit = next(
        (unit for suffix, unit in sorted(SUFFIX_UNITS.items(), key=lambda item: -len(item[0])) if key.endswith(suffix)),
        None,
    )
    return (f"{key} [{unit}]" if unit else key), 1.0


def zoomed_range(values, support) -> tuple[float, float]:
    """Where ``values`` lie (0.1 % to 99.9 % quantiles, widened by a tenth of that span each side),
    within the prior's ``support``."""
    low, high = np.quantile(values, [0.001, 0.999])
    margin = 0.1 * (high - low) or 1e-6 * max(abs(high), 1.0)
    return max(low - margin, support[0]), min(high + margin, support[1])


def corner(priors, samples, path) -> None:
    """The corner plot of ``samples`` (n, p) of the parameters of ``priors``."""
    p = len(priors)
    size = 2.6 * p + 0.8
    fig, axes = subplots(p, p, figsize=(size, size), layout="constrained", squeeze=False)
    labels = [axis_label(prior.key) for prior in priors]
    scaled = samples * np.array([factor for _, factor in labels])
    ranges = [
        tuple(np.array(zoomed_range(samples[:, j], prior.support)) * labels[j][1]) for j, prior in enumerate(priors)
    ]
    for i in range(p):
        for j in range(p):
            ax = axes[i, j]
            if j > i:
                ax.set_visible(False)
                continue
            if i == j:
                ax.hist(scaled[:, j], bins=40, range=ranges[j], color="C0", histtype="stepfilled", alpha=0.6)
                for q in np.quantile(scaled[:, j], [0.05, 0.5, 0.95]):
                    ax.axvline(q, color="k", lw=0.8, ls="-" if q == np.median(scaled[:, j]) else "--")
                ax.set_yticks([])
                ax.set_title(f"prior {priors[j].describe()}", fontsize=8)
            else:
                ax.hist2d(scaled[:, j], scaled[:, i], bins=40, range=[ranges[j], ranges[i]], cmap="Blues")
                ax.set_ylim(ranges[i])
            ax.set_xlim(ranges[j])
            if i == p - 1:
                ax.set_xlabel(labels[j][0])
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(labels[i][0])
    fig.suptitle("Posterior, zoomed to where it lies\n(dashed: 5 % and 95 %; each prior above its column)", fontsize=10)
    save(fig, path)


def predictive(sensors, distances, records, covariances, predicted, residuals, path, misfit=None) -> None:
    """Measured observables per sensor beside the posterior predictive band, and their residuals.

    ``distances`` (n,): each sensor's distance from the struck bead [bead diameters]; ``records``
    (R, m) and ``covariances`` (R, m, m): the measured records' observables and noise;
    ``predicted`` (S, m): draws of the posterior predictive distribution of a typical record (the
    band); ``residuals`` (R, m): each record's observables less the median of its own posterior
    predictive distribution (its noise, its packing's scale λ_r), in units of its standard deviation;
    ``misfit`` (R,): the records that do not fit the model, marked."""
    misfit = np.zeros(len(records), bool) if misfit is None else np.asarray(misfit, bool)
    n = len(sensors)
    x = np.asarray(distances, float)
    to_ms = ARRIVAL_UNIT_S * 1e3
    peaks = np.exp(records[:, :n])
    arrivals = np.column_stack([np.zeros(len(records)), records[:, n:]]) * to_ms
    noise = np.sqrt(np.mean(np.diagonal(covariances, axis1=1, axis2=2), axis=0))
    fig, axes = subplots(
        2, 2, figsize=(11, 7.5), layout="constrained", sharex=True, gridspec_kw={"height_ratios": [3, 2]}
    )
    (ax_peak, ax_arrival), (z_peak, z_arrival) = axes
    predicted_peaks = np.exp(predicted[:, :n])
    predicted_arrivals = np.column_stack([np.zeros(len(predicted)), predicted[:, n:]]) * to_ms
    for ax, measured, draws, error in (
        (ax_peak, peaks, predicted_peaks, peaks.mean(axis=0) * noise[:n]),
        (ax_arrival, arrivals, predicted_arrivals, np.r_[0.0, noise[n:]] * to_ms),
    ):
        low, median, high = np.quantile(draws, [0.05, 0.5, 0.95], axis=0)
        order = np.argsort(x)
        ax.fill_between(x[order], low[order], high[order], color="0.8", label="posterior predictive 90 %")
        ax.plot(x[order], median[order], color="0.4", ls=":", label="posterior predictive median")
        ax.errorbar(x, measured.mean(axis=0), yerr=error, fmt="o", color="k", capsize=3, label="measured (mean, noise)")
        if len(records) > 1:
            ax.plot(np.tile(x, len(records)), measured.ravel(), ".", color="C3", alpha=0.5, label="measured records")
        if misfit.any():
            ax.plot(
                np.tile(x, misfit.sum()),
                measured[misfit].ravel(),
                "x",
                color="C1",
                ms=8,
                mew=2,
                label="records that do not fit (p < 0.01)",
            )
    ax_peak.set_yscale("log")
    plain_log_ticks(ax_peak.yaxis)
    ax_peak.set_ylabel("peak speed [m/s]")
    ax_peak.set_title("Peak speed at each sensor")
    ax_arrival.set_ylabel(f"arrival after sensor {sensors[0]} [ms]")
    ax_arrival.set_title("Relative arrival time")
    for ax, columns, shown in ((z_peak, slice(0, n), x), (z_arrival, slice(n, None), x[1:])):
        ax.axhspan(-2, 2, color="0.92")
        ax.axhspan(-1, 1, color="0.82")
        ax.axhline(0, color="0.4", lw=0.8)
        for r, row in enumerate(residuals[:, columns]):
            ax.plot(
                shown,
                row,
                "x" if misfit[r] else "o",
                color="C1" if misfit[r] else "C3",
                ms=7 if misfit[r] else 4,
                mew=2 if misfit[r] else 1,
            )
        ax.set_ylabel("residual [predictive s.d.]")
        ax.set_xlabel("distance from the struck bead [d]")
    z_peak.set_title("Log peak speed: measured − predicted", fontsize=10)
    z_arrival.set_title("Relative arrival: measured − predicted", fontsize=10)
    for ax in (ax_peak, ax_arrival):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        for sensor, distance in zip(sensors, x):
            ax.annotate(
                str(sensor),
                (distance, 1.0),
                xycoords=("data", "axes fraction"),
                ha="center",
                va="bottom",
                fontsize=7,
                xytext=(0, 2),
                textcoords="offset points",
            )
    save(fig, path)
