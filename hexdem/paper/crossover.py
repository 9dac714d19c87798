r"""Weak disorder across the contact scale: where the ideal lattice stops and the disordered one begins.

The disorder study's σ ∈ {1, …, 6} tol (12.7–76 µm) all lie far above the overlaps in the
packing, so they cannot say where disorder starts to matter. This sweep adds σ from 1e-3 tol up
(:data:`~hexdem.paper.settings.CROSSOVER_SIGMA_PER_TOL`), every ensemble prepared as the paper's
and struck at 0.25, 0.40 and 0.70 m/s, and reads the transmission (disordered / ideal, as the
study defines it: peak over the run and leading pulse, lines 0° and ±30°) against σ and against
σ / δ(V), δ(V) the largest overlap of two beads meeting at the striker speed V,
:math:`δ = (5 μ V^2 / 4A)^{2/5} ∝ V^{4/5}` (Hertz; μ = m/2, A the pair's Hertz coefficient).

**The crossover** of each (V, line, measure) is fitted (:func:`fit_crossover`) as a step in log σ,

.. math::

    T(σ) = T_∞ + \frac{T_0 − T_∞}{1 + (σ/σ_c)^p},

weighted by the realizations' standard errors: :math:`σ_c` is the σ at half the drop from the
small-σ plateau :math:`T_0` to the large-σ one :math:`T_∞`, with its standard error from the
fit's covariance. A drop within two standard errors of zero, or a σ_c outside the sweep or
uncertain by more than half a decade, is no measured crossover.

**The overlap hypothesis** (:func:`overlap_test`): if the impact's overlap sets the crossover,
:math:`σ_c ∝ V^{4/5}` and the curves against σ/δ(V) collapse. For each line and measure the slope of
log σ_c against log V is fitted with its error and compared with 4/5 and with 0 (a crossover
that ignores V, set by something the impact does not change, e.g. the static overlaps).
"""

from __future__ import annotations

import itertools
import warnings

import numpy as np
from scipy.optimize import OptimizeWarning, curve_fit

from hexdem.disorder.preparation import TOLERANCE_M
from hexdem.model.hertz import max_overlap
from hexdem.model.materials import PAPER_DIAMETER_M, STEEL_316, hertz_coefficient, sphere_mass
from hexdem.paper.disorder_study import LINES, MEASURES, json_number

#: Columns of ``disorder_crossover.csv`` (a contract).
CROSSOVER_COLUMNS = (
    "v_striker",
    "line",
    "measure",
    "sigma_tol",
    "sigma_over_overlap",
    "transmission",
    "sem",
    "realizations",
)
#: The slope of log σ_c against log V that the overlap hypothesis predicts.
OVERLAP_EXPONENT = 0.8
#: A crossover counts as measured when log10 σ_c is known to this many decades (a factor of 3).
MAX_LOG_SIGMA_C_SE = 0.5
#: Standard errors below this are raised to it in the fit (a realization-to-realization spread
#: of 1e-4 in transmission is below what the definition of the peak resolves).
MIN_SEM = 1e-3


def impact_overlap_m(v_striker_m_s: float, diameter_m: float = PAPER_DIAMETER_M) -> float:
    """δ(V) [m]: the largest overlap of two steel beads of ``diameter_m`` meeting head-on at V."""
    mass = float(sphere_mass(diameter_m, STEEL_316))
    return float(max_overlap(mass / 2, float(hertz_coefficient(diameter_m, STEEL_316)), v_striker_m_s))


def crossover_rows(summaries: list[dict]) -> list[tuple]:
    """Rows of ``disorder_crossover.csv`` from the summaries of the prestressed ensembles with σ > 0."""
    rows = []
    for s in sorted(summaries, key=lambda s: s["sigma_per_tol"]):
        if s["preparation"] != "prestressed" or s["sigma_per_tol"] <= 0:
            continue
        for measure, key in MEASURES.items():
            for effect in s[key]:
                if effect["line"] not in LINES:
                    continue
                v = float(effect["v_striker"])
                sigma_m = s["sigma_per_tol"] * TOLERANCE_M
                rows.append(
                    (
                        v,
                        effect["line"],
                        measure,
                        s["sigma_per_tol"],
                        sigma_m / impact_overlap_m(v),
                        json_number(effect["mean_ratio"]),
                        json_number(effect["sem_ratio"]),
                        int(effect["realizations"]),
                    )
                )
    return sorted(rows, key=lambda r: (r[0], r[1], r[2], r[3]))


def _step(log_sigma, t0, t_inf, log_sigma_c, p):
    return t_inf + (t0 - t_inf) / (1.0 + 10.0 ** (p * (log_sigma - log_sigma_c)))


def fit_crossover(sigma_tol, transmission, sem) -> dict:
    """The step T(σ) (module docstring) through the points (σ/tol, T ± sem): ``sigma_c_tol`` and
    its standard error ``sigma_c_se_tol`` (from that of log σ_c), ``log10_sigma_c`` ±
    ``log10_sigma_c_se``, ``t0``, ``t_inf``, ``drop`` = T_0 − T_∞ ± ``drop_se``, the width
    exponent ``p``; ``significant`` when the drop exceeds two standard errors and σ_c lies
    within the sampled range, known to :data:`MAX_LOG_SIGMA_C_SE` decades (otherwise σ_c is
    NaN: no crossover measured)."""
    x, t = np.log10(np.asarray(sigma_tol, float)), np.asarray(transmission, float)
    err = np.maximum(np.nan_to_num(np.asarray(sem, float), nan=MIN_SEM), MIN_SEM)
    keep = np.isfinite(t)
    x, t, err = x[keep], t[keep], err[keep]
    failed = {
        "sigma_c_tol": float("nan"),
        "sigma_c_se_tol": float("nan"),
        "log10_sigma_c": float("nan"),
        "log10_sigma_c_se": float("nan"),
        "t0": float("nan"),
        "t_inf": float("nan"),
        "drop": float("nan"),
        "drop_se": float("nan"),
        "p": float("nan"),
        "significant": False,
    }
    if len(x) < 5:
        return failed
    start = (t[0], t[-1], float(np.median(x)), 2.0)
    bounds = ([-np.inf, -np.inf, x.min() - 1.0, 0.3], [np.inf, np.inf, x.max() + 1.0, 10.0])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", OptimizeWarning)
            params, cov = curve_fit(_step, x, t, p0=start, sigma=err, absolute_sigma=True, bounds=bounds, maxfev=20000)
    except (RuntimeError, ValueError):
        return failed
    t0, t_inf, log_c, p = (float(v) for v in params)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, np.inf))
    drop_se = float(np.sqrt(max(cov[0, 0] + cov[1, 1] - 2 * cov[0, 1], 0.0)))
    significant = bool(abs(t0 - t_inf) > 2 * drop_se and x.min() <= log_c <= x.max() and se[2] <= MAX_LOG_SIGMA_C_SE)
    sigma_c = 10.0**log_c if significant else float("nan")
    return {
        "sigma_c_tol": sigma_c,
        "sigma_c_se_tol": sigma_c * np.log(10.0) * float(se[2]),
        "log10_sigma_c": log_c if significant else float("nan"),
        "log10_sigma_c_se": float(se[2]) if significant else float("nan"),
        "t0": t0,
        "t_inf": t_inf,
        "drop": t0 - t_inf,
        "drop_se": drop_se,
        "p": p,
        "significant": significant,
    }


def crossover_fits(rows: list[tuple]) -> list[dict]:
    """:func:`fit_crossover` of every (V, line, measure) of ``rows``, with σ_c/δ(V)."""
    fits = []
    for v, line, measure in sorted({(r[0], r[1], r[2]) for r in rows}):
        chosen = [r for r in rows if (r[0], r[1], r[2]) == (v, line, measure)]
        fit = fit_crossover([r[3] for r in chosen], [r[5] for r in chosen], [r[6] for r in chosen])
        overlap_tol = impact_overlap_m(v) / TOLERANCE_M
        fits.append(
            {
                "v_striker": v,
                "line": line,
                "measure": measure,
                "overlap_m": impact_overlap_m(v),
                **fit,
                "sigma_c_over_overlap": fit["sigma_c_tol"] / overlap_tol,
                "sigma_c_over_overlap_se": fit["sigma_c_se_tol"] / overlap_tol,
            }
        )
    return fits


def _slope(log_v, log_c, se) -> tuple[float, float]:
    """Weighted least-squares slope of log_c against log_v and its standard error."""
    w = 1.0 / np.asarray(se) ** 2
    x_mean = np.sum(w * log_v) / np.sum(w)
    sxx = np.sum(w * (log_v - x_mean) ** 2)
    slope = np.sum(w * (log_v - x_mean) * log_c) / sxx
    return float(slope), float(np.sqrt(1.0 / sxx))


def overlap_test(fits: list[dict]) -> list[dict]:
    """Per line and measure: the slope of log σ_c against log V ± its error, and whether it is
    consistent (within two errors) with 4/5, the overlap's exponent, and with 0."""
    tests = []
    for line in LINES:
        for measure in MEASURES:
            chosen = [f for f in fits if f["line"] == line and f["measure"] == measure and f["significant"]]
            entry = {
                "line": line,
                "measure": measure,
                "speeds": [f["v_striker"] for f in chosen],
                "slope": float("nan"),
                "slope_se": float("nan"),
                "consistent_with_overlap": None,
                "consistent_with_constant": None,
            }
            if len(chosen) >= 2 and len({f["v_striker"] for f in chosen}) >= 2:
                slope, se = _slope(
                    np.log10([f["v_striker"] for f in chosen]),
                    np.array([f["log10_sigma_c"] for f in chosen]),
                    np.array([f["log10_sigma_c_se"] for f in chosen]),
                )
                entry.update(
                    slope=slope,
                    slope_se=se,
                    consistent_with_overlap=bool(abs(slope - OVERLAP_EXPONENT) <= 2 * se),
                    consistent_with_constant=bool(abs(slope) <= 2 * se),
                )
            tests.append(entry)
    return tests


def crossover_verdict(fits: list[dict], tests: list[dict]) -> str:
    """What the data say about the crossover and the overlap hypothesis, in a few sentences."""
    sentences = []
    for test in tests:
        name = f"{test['line']}° ({test['measure']})"
        found = [f for f in fits if f["line"] == test["line"] and f["measure"] == test["measure"] and f["significant"]]
        if not found:
            sentences.append(
                f"{name}: no crossover measured in the range swept (no drop beyond two standard "
                "errors, or none placed within it to half a decade)."
            )
            continue
        where = ", ".join(
            f"σ_c = {f['sigma_c_tol']:.3g} ± {f['sigma_c_se_tol']:.2g} tol "
            f"({f['sigma_c_over_overlap']:.3g} δ) at {f['v_striker']:.2f} m/s"
            for f in found
        )
        if test["consistent_with_overlap"] is None:
            sentences.append(f"{name}: {where}; too few speeds to test σ_c ∝ V to the power 4/5.")
            continue
        reading = (
            "consistent with the overlap's 4/5" if test["consistent_with_overlap"] else "not the overlap's 4/5"
        ) + (", and with no dependence on V" if test["consistent_with_constant"] else "")
        sentences.append(
            f"{name}: {where}; σ_c ∝ V to the power {test['slope']:.2f} ± {test['slope_se']:.2f}, {reading}."
        )
    return " ".join(sentences)


#: Headers of the crossover's two tables, in the report (section 3b) and on the crossover page.
FIT_TABLE_HEADER = ("V [m/s]", "line", "measure", "σ_c / tol", "σ_c / δ(V)", "T₀ (small σ)", "T∞ (large σ)")
OVERLAP_TABLE_HEADER = ("line", "measure", "slope", "consistent with 4/5", "consistent with 0")


def _missing(value) -> bool:
    """NaN, or null once written to JSON."""
    return value is None or not np.isfinite(value)


def _shown(value, pattern: str) -> str:
    """``value`` formatted, or "–" where it is missing."""
    return "–" if _missing(value) else format(value, pattern)


def fit_table(fits: list[dict]) -> list[tuple[str, ...]]:
    """The rows of :data:`FIT_TABLE_HEADER`: each (V, line, measure)'s σ_c ± its standard error,
    in tol and in δ(V) ("–": no crossover measured), and the step's plateaus."""
    return [
        (
            f"{f['v_striker']:.2f}",
            f["line"],
            f["measure"],
            f"{_shown(f['sigma_c_tol'], '.3g')} ± {_shown(f['sigma_c_se_tol'], '.2g')}" if f["significant"] else "–",
            f"{_shown(f['sigma_c_over_overlap'], '.3g')} ± {_shown(f['sigma_c_over_overlap_se'], '.2g')}"
            if f["significant"]
            else "–",
            _shown(f["t0"], ".3f"),
            _shown(f["t_inf"], ".3f"),
        )
        for f in fits
    ]


def overlap_table(tests: list[dict]) -> list[tuple[str, ...]]:
    """The rows of :data:`OVERLAP_TABLE_HEADER`: the slope of log σ_c against log V per line and measure."""
    verdicts = {True: "yes", False: "no", None: "–"}
    return [
        (
            t["line"],
            t["measure"],
            "–" if _missing(t["slope_se"]) else f"{t['slope']:.2f} ± {t['slope_se']:.2f}",
            verdicts[t["consistent_with_overlap"]],
            verdicts[t["consistent_with_constant"]],
        )
        for t in tests
    ]


#: The crossover's two figures in ``disorder/``: the transmission against σ/tol, and against
#: σ/δ(V), where the overlap hypothesis collapses the speeds' curves.
CROSSOVER_FIGURES = {"tol": "disorder_crossover.png", "overlap": "disorder_crossover_overlap.png"}


def crossover_figure(rows: list[tuple], fits: list[dict], path, against: str = "tol") -> None:
    """Transmission against σ/tol (``against`` "tol") or σ/δ(V) ("overlap"): lines 0° and ±30°
    (columns), peak over the run and leading pulse (rows), one colour per striker speed: points
    ± 2 SEM, the fitted steps and their σ_c (dotted). Sized to be read in the report's column,
    about 1100 px wide: its smallest text is 10 px there."""

    from hexdem.analysis import plotting as plots

    fig, axes = plots.subplots(
        len(MEASURES), len(LINES), figsize=(10, 7.6), sharex=True, sharey=True, layout="constrained"
    )
    speeds = sorted({r[0] for r in rows})
    for (i, measure), (j, line) in itertools.product(enumerate(MEASURES), enumerate(LINES)):
        ax = axes[i, j]
        for colour, v in zip(("C0", "C1", "C3", "C2"), speeds):
            chosen = [r for r in rows if (r[0], r[1], r[2]) == (v, line, measure)]
            fit = next(f for f in fits if (f["v_striker"], f["line"], f["measure"]) == (v, line, measure))
            scale = impact_overlap_m(v) / TOLERANCE_M if against == "overlap" else 1.0
            sigma, t, sem = (np.array([r[k] for r in chosen], float) for k in (3, 5, 6))
            ax.errorbar(
                sigma / scale,
                t,
                yerr=2 * np.nan_to_num(sem),
                fmt="o",
                color=colour,
                capsize=2,
                markersize=5,
                label=f"{v:.2f} m/s",
            )
            grid = np.geomspace(sigma.min(), sigma.max(), 200)
            if fit["significant"]:
                ax.plot(
                    grid / scale,
                    _step(np.log10(grid), fit["t0"], fit["t_inf"], fit["log10_sigma_c"], fit["p"]),
                    color=colour,
                    lw=1.2,
                )
                ax.axvline(fit["sigma_c_tol"] / scale, color=colour, ls=":", lw=1.2)
        ax.set_xscale("log")
        ax.axhline(1.0, color="k", lw=0.8)
        ax.grid(True, which="both", alpha=0.3)
        ax.set_title(f"{line}°, {'peak over the run' if measure == 'peak' else 'leading pulse'}", fontsize=12)
        if i == len(MEASURES) - 1:
            ax.set_xlabel(r"$\sigma / \delta(V)$" if against == "overlap" else r"$\sigma$ / tol", fontsize=12)
        if j == 0:
            ax.set_ylabel("disordered / ideal", fontsize=12)
        ax.tick_params(labelsize=11)
    axes[0, 0].legend(fontsize=10, title="striker", title_fontsize=10)
    fig.suptitle(
        "Transmission against "
        + (r"$\sigma / \delta(V)$, $\delta(V)$ the impact's overlap" if against == "overlap" else r"$\sigma$")
        + " (mean ± 2 SEM; lines: fitted steps, dotted: $\\sigma_c$)",
        fontsize=12,
    )
    plots.save(fig, path)


def pm30_claim(rows: list[tuple]) -> str:
    """The paper's ±30° claim restated across the contact scale: where, if anywhere, the ±30°
    transmission exceeds the ideal lattice's by more than two standard errors."""
    pm30 = [r for r in rows if r[1] == "±30" and np.isfinite(r[5])]
    if not pm30:
        return "No ±30° transmission was measured."
    rises = [r for r in pm30 if r[5] - 2 * np.nan_to_num(r[6]) > 1.0]
    best = max(pm30, key=lambda r: r[5])
    span = (
        f"Across σ = {min(r[3] for r in pm30):g}–{max(r[3] for r in pm30):g} tol "
        f"(σ/δ(V) = {min(r[4] for r in pm30):.2g}–{max(r[4] for r in pm30):.2g})"
    )
    largest = (
        f"the largest ±30° transmission is {best[5]:.3f} ± {best[6]:.3f} ({best[2]}, σ = {best[3]:g} tol, "
        f"{best[0]:.2f} m/s)"
    )
    if not rises:
        return (
            f"{span} the ±30° transmission never exceeds the ideal lattice's by two standard errors; "
            f"{largest}. The paper's redistribution towards ±30° does not appear at any disorder strength, "
            "weak on the contact scale or not."
        )
    where = "; ".join(f"{r[2]}, σ = {r[3]:g} tol, {r[0]:.2f} m/s" for r in rises)
    return (
        f"{span} the ±30° transmission exceeds the ideal lattice's by more than two standard errors at: "
        f"{where}; {largest}."
    )
