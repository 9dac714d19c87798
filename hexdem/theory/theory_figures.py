"""Figures of the theory sections: the TCA against the lattice (Fig. 5, label fig:TCA) and the
scaling-law procedure (Figs. 6 and 7, labels fig:vodecay30 and fig:vodecay0), plus the
geometric-or-power diagnostic. Each function saves one PNG atomically (:func:`hexdem.analysis.plotting.save`).
"""

from __future__ import annotations

import numpy as np

from hexdem.analysis.plotting import UNIT_LABELS, save, subplots

ND_SPEED = UNIT_LABELS["nondimensional"]["speed"]


def _lattice_against_tca(n_lattice, lattice, n_tca, tca, hyperg, ylabel, title, path) -> None:
    """One quantity along the 30° line: lattice vs TCA vs eq. (6)."""
    fig, ax = subplots(figsize=(6, 4.5))
    ax.plot(n_lattice, lattice, "o", color="tab:blue", label="lattice simulation")
    ax.plot(n_tca, tca, "o", mfc="none", color="tab:red", markersize=9, label="TCA, eq. (5)")
    ax.plot(n_tca, hyperg, "^", color="k", label="TCA closed form, eq. (6)")
    ax.set_xlabel("bead n on the 30° line")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    save(fig, path)


def tca_pulse_speeds(n_lattice, lattice, n_tca, tca, hyperg, v0, path) -> None:
    """Fig. 5a: pulse speed c_n = 1/T_n against n, lattice vs TCA vs eq. (6)."""
    _lattice_against_tca(
        n_lattice,
        lattice,
        n_tca,
        tca,
        hyperg,
        "pulse speed $c_n = 1/T_n$  [d per time unit]",
        f"30° strike, 30° observation, $V_0$ = {v0:g} (nondimensional)",
        path,
    )


def tca_arrival_times(n, lattice_ms, tca_ms, hyperg_ms, v0_m_s, path) -> None:
    """Fig. 5b: arrival time of the pulse against n (physical units, 0° strike, 30° line)."""
    _lattice_against_tca(
        n,
        lattice_ms,
        n,
        tca_ms,
        hyperg_ms,
        "arrival time [ms]",
        f"0° strike, 30° observation, $V_0$ = {v0_m_s:g} m/s, steel d = 19.05 mm",
        path,
    )


def _traces(ax, trace, fit, title):
    """|v| of beads 0..last against time at the trace's V₀, their maxima and the fitted :math:`V_s c^{n−s}`.

    ``trace`` (times, speeds, peaks, t_peak, v0) of the fit's line; ``title`` without V₀.
    """
    times, speeds, peaks, t_peak, v0 = trace
    start, last = fit.combination.start, fit.last
    c = fit.c[np.argmin(abs(fit.v0 - v0))]
    fit_values = peaks[start] * c ** np.arange(last - start + 1)
    for n in range(last + 1):
        ax.plot(times, speeds[:, n], linewidth=0.8)
    ax.plot(t_peak[: last + 1], peaks[: last + 1], "k.", label="maxima $V_n$")
    ax.plot(t_peak[start : last + 1], fit_values, "r--", label=f"$V_{start}\\,c^{{n-{start}}}$")
    ax.annotate(f"$V_{start}$", (t_peak[start], peaks[start]), textcoords="offset points", xytext=(4, 4))
    ax.set_xlabel("time [nondimensional]")
    ax.set_ylabel(f"|v|  [{ND_SPEED}]")
    ax.set_title(f"{title}, $V_0$ = {v0:.3g}")
    ax.legend()


def _start_speed_panel(ax, fit, ylabel, title, extra=None):
    """Measured V_s against V₀ and the fitted V₀ (V_s/V₀)(V₀)."""
    ax.plot(fit.v0, fit.v_start, "o", label="simulations")
    grid = np.linspace(fit.v0.min(), fit.v0.max(), 200)
    ax.plot(grid, grid * fit.law.start_ratio(grid), "r-", label="fit")
    if extra is not None:
        ax.plot(grid, extra[1](grid), "k:", label=extra[0])
    ax.set_xlabel("$V_0$")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()


def vodecay30(trace, fit_30_30, fit_30_0, path) -> None:
    """Fig. 6: (a) the 30/30 traces with the fitted maxima; (b) c(V₀) = m V₀ + b; (c) V₁ against
    V₀; (d) V₂ against V₀ for 0° observation (30° strike)."""
    fig, axes = subplots(2, 2, figsize=(12, 9))
    law = fit_30_30.law
    _traces(axes[0, 0], trace, fit_30_30, "(a) 30° strike, 30° line")
    axes[0, 1].errorbar(fit_30_30.v0, fit_30_30.c, yerr=fit_30_30.c_stderr, fmt="o", label="per-$V_0$ fits")
    grid = np.linspace(fit_30_30.v0.min(), fit_30_30.v0.max(), 200)
    axes[0, 1].plot(grid, law.decay_rate(grid), "r-", label=f"$m V_0 + b$: m = {law.m:.4f}, b = {law.b:.4f}")
    axes[0, 1].set(xlabel="$V_0$", ylabel="decay rate c", title="(b) c($V_0$), 30/30")
    axes[0, 1].legend()
    axes[0, 1].grid(alpha=0.3)
    _start_speed_panel(axes[1, 0], fit_30_30, "$V_1$", "(c) $V_1 = \\alpha V_0^2 + \\beta V_0$, 30/30")
    _start_speed_panel(
        axes[1, 1], fit_30_0, "$V_2$", "(d) $V_2 = V_0(\\alpha V_0^2 + \\beta V_0 + \\gamma)$, 30° strike, 0° line"
    )
    fig.tight_layout()
    save(fig, path)


def vodecay0(trace, fit_0_0, fit_0_30, path) -> None:
    """Fig. 7: (a) 0/0 traces with the fit from bead 2; (b) V₁ against V₀ for 0/30 with V₀/2."""
    fig, axes = subplots(1, 2, figsize=(12, 4.5))
    _traces(axes[0], trace, fit_0_0, "(a) 0° strike, 0° line")
    _start_speed_panel(
        axes[1], fit_0_30, "$V_1$", "(b) $V_1$ against $V_0$, 0° strike, 30° line", extra=("$V_0/2$", lambda v: v / 2)
    )
    fig.tight_layout()
    save(fig, path)


def decay_rates(fits, path) -> None:
    """c(V₀) of every combination with its line m V₀ + b."""
    fig, ax = subplots(figsize=(6.5, 4.5))
    for fit in fits:
        line = ax.errorbar(fit.v0, fit.c, yerr=fit.c_stderr, fmt="o", markersize=3, label=fit.combination.name)
        ax.plot(fit.v0, fit.law.decay_rate(fit.v0), "-", color=line[0].get_color())
    ax.set(xlabel="$V_0$ (nondimensional)", ylabel="decay rate c", title="c($V_0$) = m $V_0$ + b (strike/observation)")
    ax.grid(alpha=0.3)
    ax.legend()
    save(fig, path)


def decay_form(ratios_by_combination, path) -> None:
    """Local ratio :math:`V_{n+1}/V_n` against n: flat for a geometric law, rising to 1 for a power law.

    ``ratios_by_combination``: {name: [(v0, n, ratio), ...]}.
    """
    fig, axes = subplots(1, len(ratios_by_combination), figsize=(4 * len(ratios_by_combination), 4), sharey=True)
    for ax, (name, curves) in zip(np.atleast_1d(axes), ratios_by_combination.items()):
        for v0, n, ratio in curves:
            ax.plot(n, ratio, "o-", markersize=3, label=f"$V_0$ = {v0:.3g}")
        ax.set(xlabel="n", title=f"{name} (strike/observation)")
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("$V_{n+1}/V_n$")
    np.atleast_1d(axes)[0].legend()
    fig.tight_layout()
    save(fig, path)
