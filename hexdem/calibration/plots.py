"""The calibration's figures: the posterior's corner plot and the posterior predictive check.

``posterior.png``: each parameter's marginal histogram on the diagonal, every pair's joint
histogram below it, over the prior's range, with the 5 %, 50 % and 95 % quantiles marked.
``predictive.png``: in the style of the paper's Fig. 9, each sensor's measured peak speed and
relative arrival (mean of the records, error bars one standard deviation of their noise, dots for
single records) beside the posterior predictive 90 % band: the emulated observables at the
posterior's samples, with the records' noise and the packings' spread added.
"""

from __future__ import annotations

import numpy as np

from hexdem.analysis.plotting import save, subplots
from hexdem.calibration.observables import ARRIVAL_UNIT_S


def corner(priors, samples, path) -> None:
    """The corner plot of ``samples`` (n, p) of the parameters of ``priors``."""
    p = len(priors)
    size = 2.4 * p + 0.6
    fig, axes = subplots(p, p, figsize=(size, size), layout="constrained", squeeze=False)
    ranges = [prior.support if prior.kind != "normal" else tuple(np.quantile(samples[:, j], [0.001, 0.999]))
              for j, prior in enumerate(priors)]
    for i in range(p):
        for j in range(p):
            ax = axes[i, j]
            if j > i:
                ax.set_visible(False)
                continue
            if i == j:
                ax.hist(samples[:, j], bins=40, range=ranges[j], color="C0", histtype="stepfilled", alpha=0.6)
                for q in np.quantile(samples[:, j], [0.05, 0.5, 0.95]):
                    ax.axvline(q, color="k", lw=0.8, ls="-" if q == np.median(samples[:, j]) else "--")
                ax.set_yticks([])
            else:
                ax.hist2d(samples[:, j], samples[:, i], bins=40, range=[ranges[j], ranges[i]], cmap="Blues")
                ax.set_ylim(ranges[i])
            ax.set_xlim(ranges[j])
            if i == p - 1:
                ax.set_xlabel(priors[j].key)
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(priors[i].key)
    fig.suptitle("Posterior (dashed: 5 % and 95 %)")
    save(fig, path)


def predictive(sensors, records, covariances, predicted, path) -> None:
    """Measured observables per sensor beside the posterior predictive band.

    ``records`` (R, m) and ``covariances`` (R, m, m): the measured records' observables and noise;
    ``predicted`` (S, m): draws of the posterior predictive distribution."""
    n = len(sensors)
    positions = np.arange(n)
    peaks = np.exp(records[:, :n])
    arrivals = np.column_stack([np.zeros(len(records)), records[:, n:]])
    noise = np.sqrt(np.mean(np.diagonal(covariances, axis1=1, axis2=2), axis=0))
    fig, (ax_peak, ax_arrival) = subplots(1, 2, figsize=(10, 4), layout="constrained")
    low, median, high = np.quantile(np.exp(predicted[:, :n]), [0.05, 0.5, 0.95], axis=0)
    ax_peak.fill_between(positions, low, high, color="0.8", label="posterior predictive 90 %")
    ax_peak.plot(positions, median, color="0.4", ls=":", label="posterior predictive median")
    ax_peak.errorbar(positions, peaks.mean(axis=0), yerr=peaks.mean(axis=0) * noise[:n], fmt="o", color="k",
                     capsize=3, label="measured (mean, noise)")
    if len(records) > 1:
        ax_peak.plot(np.repeat(positions[None], len(records), 0).ravel(), peaks.ravel(), ".", color="C3", alpha=0.5,
                     label="measured records")
    ax_peak.set_yscale("log")
    ax_peak.set_ylabel("peak speed [m/s]")
    ax_peak.set_title("Peak speed at each sensor")
    rel = np.column_stack([np.zeros(len(predicted)), predicted[:, n:]]) * ARRIVAL_UNIT_S * 1e3
    low, median, high = np.quantile(rel, [0.05, 0.5, 0.95], axis=0)
    ax_arrival.fill_between(positions, low, high, color="0.8", label="posterior predictive 90 %")
    ax_arrival.plot(positions, median, color="0.4", ls=":")
    ax_arrival.errorbar(positions, arrivals.mean(axis=0) * ARRIVAL_UNIT_S * 1e3,
                        yerr=np.r_[0.0, noise[n:]] * ARRIVAL_UNIT_S * 1e3, fmt="o", color="k", capsize=3,
                        label="measured (mean, noise)")
    ax_arrival.set_ylabel(f"arrival after sensor {sensors[0]} [ms]")
    ax_arrival.set_title("Relative arrival time")
    for ax in (ax_peak, ax_arrival):
        ax.set_xticks(positions, [str(s) for s in sensors])
        ax.set_xlabel("sensor")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    save(fig, path)
