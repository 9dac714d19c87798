r"""Velocity-decay scaling laws of Sec. V: per-V₀ decay fits and the laws c(V₀), V_s/V₀.

Everything is nondimensional (A = d = M = 1, eq. scaling) unless it says otherwise. The
peak speeds come from a sweep of impact velocities V₀ (:mod:`hexdem.theory.sweep`); the files and
figures from :mod:`hexdem.theory.outputs`.

**Combinations.** Each strike angle (0°, 30°) is observed along the 0° and +30° lines of
the struck lattice. The four strike/observation combinations:

=========  ============  ========  ==========  ================================
name       strike, line  start s   law         V_s / V₀
=========  ============  ========  ==========  ================================
``30/30``  30°, +30      1         eq. (9)     α V₀ + β
``30/0``   30°, 0        2         eq. (10)    α V₀² + β V₀ + γ
``0/0``    0°, 0         2         eq. (10)    α V₀² + β V₀ + γ
``0/30``   0°, +30       1         eq. (11)    α V₀² + β V₀ + γ
=========  ============  ========  ==========  ================================

**Per-V₀ fit** (:func:`fit_decay`). :math:`V_n = V_s c^{n − s}` on the window s < n ≤ ``last``, with
V_s the measured peak of the start bead (the paper's "V₁ is the maximum velocity of the
first bead"), so c is the only free parameter (a free V_s is the other reading the fit
protocol search of :mod:`hexdem.theory.protocols` tries). ``kind="loglinear"`` (default) regresses
log(V_n / V_s) on n − s through the origin; ``kind="nonlinear"`` is least squares on V_n
itself (``scipy.optimize.curve_fit``). Both return c and its standard error, which for an
anchored start is conditional on V_s (the measured start bead is taken as exact).

**Laws.** c(V₀) = m V₀ + b and V_s/V₀ = the polynomial above are ordinary least squares
(:func:`polynomial_fit`), with standard errors from the residual variance. Together:
:math:`V_n = V_0\, (V_s/V_0)(V_0)\, (m V_0 + b)^{n − s}`, eqs. (9), (10), (11).

**Why c depends on V₀ at all.** The Hertz lattice with linearised bond directions is scale
invariant (:math:`x → λx,\ t → λ^{−1/4} t`): c would be a constant. V₀ enters only through the
geometric nonlinearity of the bond lengths |d e + q_j − q_i|, whose relative size grows with
the overlaps :math:`δ ∝ V_0^{4/5}` (δ ≈ 0.3 d at V₀ = 0.3). So m measures geometric nonlinearity
and b is the law's small-amplitude intercept (c(V₀) is slightly convex over the sweep, so b
lies a little below the measured c at the smallest V₀). The sweep's V₀ = 0.01 … 0.30 are
41 … 1230 m/s for the paper's steel beads; the experiment's 0.4 m/s is V₀ ≈ 1e−4, where the
law gives c = b to 4 digits.

**Physical units** (:meth:`ScalingLaw.physical`) and **the decay's form** (:func:`decay_form_test`,
beyond the paper) are stated where they are computed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError


@dataclass(frozen=True)
class Combination:
    """A strike/observation combination: ``strike_deg``, observation ``line`` (lattice line
    name), ``start`` bead s of the fits, ``equation`` label and ``degree`` of V_s/V₀ in V₀."""

    name: str
    strike_deg: float
    line: str
    start: int
    equation: str
    degree: int


COMBINATIONS = {
    c.name: c
    for c in (
        Combination("30/30", 30.0, "+30", 1, "v30", 1),
        Combination("30/0", 30.0, "0", 2, "v0", 2),
        Combination("0/0", 0.0, "0", 2, "v0", 2),
        Combination("0/30", 0.0, "+30", 1, "veq0", 2),
    )
}
FIT_KINDS = ("loglinear", "nonlinear")
#: Default last bead of the fit windows (the paper's Figs. 6a and 7a show beads 0–12).
DEFAULT_LAST = 12


# --------------------------------------------------------------------------- fits


@dataclass(frozen=True)
class Fit:
    """Least-squares parameters in the manner of ``curve_fit``: ``values`` (popt),
    ``covariance`` (pcov, scaled by the residual variance), ``names``, ``rss`` (residual sum
    of squares), ``dof`` (points minus parameters)."""

    names: tuple[str, ...]
    values: np.ndarray
    covariance: np.ndarray
    rss: float
    dof: int

    @property
    def stderr(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    def __getitem__(self, name: str) -> float:
        return float(self.values[self.names.index(name)])

    def error(self, name: str) -> float:
        return float(self.stderr[self.names.index(name)])


def polynomial_fit(x, y, degree: int, names) -> Fit:
    r"""Ordinary least squares of :math:`y = \sum_k p_k x^{\text{degree}−k}` (highest power first,
    as ``np.polyfit``)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    design = np.vander(x, degree + 1)
    dof = len(x) - (degree + 1)
    if dof < 1:
        raise HexdemError(f"a degree-{degree} fit needs more than {degree + 1} points, got {len(x)}")
    values, *_ = np.linalg.lstsq(design, y, rcond=None)
    residual = y - design @ values
    rss = float(residual @ residual)
    covariance = rss / dof * np.linalg.inv(design.T @ design)
    return Fit(tuple(names), values, covariance, rss, dof)


def fit_decay(n, v, start: int, last: int, kind: str = "loglinear", anchored: bool = True) -> tuple[float, float]:
    """(c, stderr of c) of :math:`V_n = V_s c^{n − s}`, s = ``start``, from one line's peak speeds.

    ``n`` bead numbers and ``v`` peak speeds of one line (n ascending from 0). Anchored (the
    paper's reading), V_s = v[start] is the measured peak and the window is s < n ≤ last (the
    stderr treats V_s as exact); free, V_s is a second parameter fitted with c over
    s ≤ n ≤ last.
    """
    if kind not in FIT_KINDS:
        raise HexdemError(f"unknown fit type {kind!r}; use one of: {', '.join(FIT_KINDS)}")
    n, v = np.asarray(n), np.asarray(v, float)
    window = (n > start - (not anchored)) & (n <= last)
    if np.count_nonzero(window) < 2 + (not anchored):
        raise HexdemError(f"the window {start}..{last} needs at least two beads after the start bead")
    k, vk = n[window] - start, v[window]
    anchor = v[n == start][0]
    if not (np.all(vk > 0) and anchor > 0):  # (NaN: still rising at the end; 0: never reached)
        raise HexdemError(f"peak speeds missing in the window {start}..{last}: the run was too short")
    if anchored:
        y, design = np.log(vk / anchor), k[:, None].astype(float)
    else:
        y, design = np.log(vk), np.vander(k.astype(float), 2)
    coefficients, *_ = np.linalg.lstsq(design, y, rcond=None)
    residual = y - design @ coefficients
    covariance = residual @ residual / (len(k) - design.shape[1]) * np.linalg.inv(design.T @ design)
    c, c_err = math.exp(coefficients[0]), math.exp(coefficients[0]) * math.sqrt(covariance[0, 0])
    if kind == "nonlinear":
        from scipy.optimize import curve_fit  # here: a sweep's run imports this module and need not load scipy

        if anchored:
            popt, pcov = curve_fit(lambda kk, cc: anchor * cc**kk, k.astype(float), vk, p0=[c])
        else:
            popt, pcov = curve_fit(
                lambda kk, cc, amplitude: amplitude * cc**kk, k.astype(float), vk, p0=[c, math.exp(coefficients[1])]
            )
        c, c_err = float(popt[0]), float(np.sqrt(pcov[0, 0]))
    return c, c_err


@dataclass(frozen=True)
class ScalingLaw:
    r""":math:`V_n = V_0 P(V_0)\, (m V_0 + b)^{n − \text{start}}`: eqs. (9), (10), (11).

    ``amplitude`` the coefficients of P highest power first: (α, β) or (α, β, γ);
    ``velocity_unit_m_s`` 1 for nondimensional laws, U for laws in m/s.
    """

    combination: str
    start: int
    m: float
    b: float
    amplitude: tuple[float, ...]
    velocity_unit_m_s: float = 1.0

    def decay_rate(self, v0):
        return self.m * np.asarray(v0) + self.b

    def start_ratio(self, v0):
        """V_start / V₀ = P(V₀)."""
        return np.polyval(self.amplitude, np.asarray(v0, float))

    def __call__(self, v0, n):
        """Predicted peak speed of bead n ≥ start."""
        v0 = np.asarray(v0, float)
        return v0 * self.start_ratio(v0) * self.decay_rate(v0) ** (np.asarray(n) - self.start)

    def physical(self, velocity_unit_m_s: float) -> ScalingLaw:
        r"""The same law for V₀ and V_n in m/s: every V becomes V/U, :math:`U = d^{5/4} \sqrt{A/M}`
        (``velocity_unit_m_s``, end of Sec. V), so m and the V₀-powers of the polynomial pick up
        powers of 1/U."""
        u = float(velocity_unit_m_s)
        degree = len(self.amplitude) - 1
        amplitude = tuple(p / u ** (degree - k) for k, p in enumerate(self.amplitude))
        return ScalingLaw(self.combination, self.start, self.m / u, self.b, amplitude, u)


@dataclass(frozen=True)
class CombinationFit:
    """The scaling laws of one strike/observation combination, fitted over a V₀ sweep (Sec. V).

    Attributes
    ----------
    combination : Combination
        The strike and observation lines, and the laws' form (eqs. (9)–(11)).
    last : int
        The fit window's last bead.
    kind : {"loglinear", "nonlinear"}
        How each V₀'s decay V_n = V_s cⁿ was fitted.
    v0 : numpy.ndarray of float, shape (K,)
        The sweep's striking speeds (nondimensional).
    c, c_stderr : numpy.ndarray of float, shape (K,)
        The decay factor per layer at each V₀, and its standard error.
    v_start : numpy.ndarray of float, shape (K,)
        The measured V_s at each V₀ (the law's starting speed, eqs. (9)–(11)).
    rate : Fit
        The fit of c = m V₀ + b (``rate["m"]``, ``rate["b"]``, ``rate.error("m")``).
    ratio : Fit
        The fit of V_s / V₀ (α, β[, γ]).
    """

    combination: Combination
    last: int
    kind: str
    v0: np.ndarray
    c: np.ndarray
    c_stderr: np.ndarray
    v_start: np.ndarray
    rate: Fit
    ratio: Fit

    @property
    def law(self) -> ScalingLaw:
        return ScalingLaw(
            self.combination.name, self.combination.start, self.rate["m"], self.rate["b"], tuple(self.ratio.values)
        )

    def summary(self, velocity_unit_m_s: float) -> dict:
        """The ``scaling.json`` entry: coefficients, standard errors, window, V₀ range."""
        names = ("alpha", "beta", "gamma")
        coefficients = {"m": self.rate["m"], "b": self.rate["b"]}
        errors = {"m": self.rate.error("m"), "b": self.rate.error("b")}
        for name in names:
            present = name in self.ratio.names
            coefficients[name] = self.ratio[name] if present else None
            errors[name] = self.ratio.error(name) if present else None
        physical = self.law.physical(velocity_unit_m_s)
        degree = self.combination.degree
        return {
            **coefficients,
            "stderr": errors,
            "start_bead": self.combination.start,
            "window": [self.combination.start, self.last],
            "fit": self.kind,
            "v0_range": [float(self.v0.min()), float(self.v0.max())],
            "n_v0": len(self.v0),
            "strike_deg": self.combination.strike_deg,
            "observation_line": self.combination.line,
            "equation": self.combination.equation,
            "law": f"V_n = V0 ({_polynomial_text(degree)}) (m V0 + b)^(n - {self.combination.start}), "
            f"n >= {self.combination.start}",
            "rms_relative_residual_c": float(np.sqrt(self.rate.rss / len(self.v0)) / np.mean(self.c)),
            "physical": {
                "units": f"V0, V_n in m/s; m in s/m; alpha in (s/m)^{degree}; beta in (s/m)^{degree - 1}",
                "velocity_unit_m_s": velocity_unit_m_s,
                "m": physical.m,
                "b": physical.b,
                **dict(zip(names, list(physical.amplitude) + [None] * (3 - len(physical.amplitude)))),
            },
        }


def _polynomial_text(degree: int) -> str:
    return "alpha V0 + beta" if degree == 1 else "alpha V0^2 + beta V0 + gamma"


def fit_combination(
    combination: Combination, v0, peaks, last: int = DEFAULT_LAST, kind: str = "loglinear"
) -> CombinationFit:
    """Fit one combination: ``peaks`` (K, L) peak speeds V_n of its line for each V₀ of ``v0``."""
    v0, peaks = np.asarray(v0, float), np.asarray(peaks, float)
    start = combination.start
    if not start + 2 <= last < peaks.shape[1]:
        raise HexdemError(
            f"{combination.name}: the window's last bead must lie in {start + 2}..{peaks.shape[1] - 1}, got {last}"
        )
    n = np.arange(peaks.shape[1])
    decay = np.array([fit_decay(n, row, start, last, kind) for row in peaks])
    v_start = peaks[:, start]
    rate = polynomial_fit(v0, decay[:, 0], 1, ("m", "b"))
    ratio = polynomial_fit(v0, v_start / v0, combination.degree, ("alpha", "beta", "gamma")[: combination.degree + 1])
    return CombinationFit(combination, last, kind, v0, decay[:, 0], decay[:, 1], v_start, rate, ratio)


def sensitivity(combination: Combination, v0, peaks, lasts=None) -> list[dict]:
    """(m, b) and their standard errors for every window end in ``lasts`` (default: all the
    beads of ``peaks``) and both fit types."""
    peaks = np.asarray(peaks, float)
    lasts = range(combination.start + 2, peaks.shape[1]) if lasts is None else lasts
    rows = []
    for last in lasts:
        for kind in FIT_KINDS:
            fit = fit_combination(combination, v0, peaks, last, kind)
            rows.append(
                {
                    "combination": combination.name,
                    "last": last,
                    "fit": kind,
                    "m": fit.rate["m"],
                    "m_stderr": fit.rate.error("m"),
                    "b": fit.rate["b"],
                    "b_stderr": fit.rate.error("b"),
                }
            )
    return rows


# ----------------------------------------------------------- geometric or power law in n

#: Thresholds on the drift fraction φ (see :class:`DecayFormTest`).
GEOMETRIC_BELOW, POWER_ABOVE = 1 / 3, 2 / 3


@dataclass(frozen=True)
class DecayFormTest:
    """Geometric :math:`V_n = A q^n` against power :math:`V_n = A n^{−p}` on one line at one V₀.

    Both are straight-line fits in log V (against n, against log n) with two parameters:
    ``rss_geometric`` and ``rss_power`` are their residual sums of squares in log V, directly
    comparable. ``q`` and ``p`` the fitted ratio and exponent. The local ratio
    :math:`r_n = V_{n+1}/V_n` is constant for a geometric law and rises as :math:`(n/(n+1))^p` for
    a power law: ``ratio_slope``
    ± ``ratio_slope_stderr`` is the least-squares trend of the measured r_n per bead,
    ``power_ratio_slope`` the same trend of the fitted power law's r_n, and
    ``drift_fraction`` φ = their quotient (0: geometric, 1: power).
    """

    rss_geometric: float
    rss_power: float
    q: float
    p: float
    ratio_slope: float
    ratio_slope_stderr: float
    power_ratio_slope: float

    @property
    def drift_fraction(self) -> float:
        return self.ratio_slope / self.power_ratio_slope

    @property
    def verdict(self) -> str:
        """ "geometric" or "power" when the residuals and the ratio drift agree, else "neither"."""
        if self.rss_geometric < self.rss_power and self.drift_fraction < GEOMETRIC_BELOW:
            return "geometric"
        if self.rss_power < self.rss_geometric and self.drift_fraction > POWER_ABOVE:
            return "power"
        return "neither"


def decay_form_test(v, start: int, last: int) -> DecayFormTest:
    r"""Compare the geometric and power forms on beads start … last (start ≥ 1) of one line.

    The paper calls the decay a power law but fits a geometric law in n. Both are two-parameter
    straight lines, log V_n against n or against log n, so their residual sums of squares compare
    directly; the residual curvature and the drift of the local ratio :math:`V_{n+1}/V_n` (constant
    for a geometric law, rising towards 1 as :math:`(n/(n+1))^p` for a power law) say which one the
    data follow."""
    if start < 1 or last - start < 3:
        raise HexdemError(f"the form test needs 1 <= start and at least 4 beads, got {start}..{last}")
    v = np.asarray(v, float)
    n = np.arange(start, last + 1).astype(float)
    log_v = np.log(v[start : last + 1])
    geometric = polynomial_fit(n, log_v, 1, ("slope", "intercept"))
    power = polynomial_fit(np.log(n), log_v, 1, ("slope", "intercept"))
    p = -power["slope"]
    drift = polynomial_fit(n[:-1], v[start + 1 : last + 1] / v[start:last], 1, ("slope", "intercept"))
    power_drift = polynomial_fit(n[:-1], (n[:-1] / n[1:]) ** p, 1, ("slope", "intercept"))
    return DecayFormTest(
        geometric.rss,
        power.rss,
        math.exp(geometric["slope"]),
        p,
        drift["slope"],
        drift.error("slope"),
        power_drift["slope"],
    )


def decay_form_summary(tests, v0) -> dict:
    """Verdict over a V₀ sweep of one line: counts of each per-V₀ verdict, the median drift
    fraction φ, how often each form has the smaller residuals, and the overall verdict (the
    per-V₀ verdict of the majority, "mixed" without one)."""
    verdicts = [t.verdict for t in tests]
    counts = {form: verdicts.count(form) for form in ("geometric", "power", "neither")}
    winner = max(counts, key=counts.get)
    return {
        "verdict": winner if counts[winner] > len(tests) / 2 else "mixed",
        "verdict_counts": counts,
        "smaller_rss_counts": {
            "geometric": sum(t.rss_geometric < t.rss_power for t in tests),
            "power": sum(t.rss_power <= t.rss_geometric for t in tests),
        },
        "median_drift_fraction": float(np.median([t.drift_fraction for t in tests])),
        "ratio_slope_per_bead": {
            "at_v0_min": tests[0].ratio_slope,
            "at_v0_max": tests[-1].ratio_slope,
            "v0_min": float(v0[0]),
            "v0_max": float(v0[-1]),
        },
        "median_rss_power_over_geometric": float(np.median([t.rss_power / t.rss_geometric for t in tests])),
    }
