"""Velocity-decay scaling laws of Sec. V, from a sweep of impact velocities V₀.

Everything is nondimensional (A = d = M = 1, eq. scaling) unless it says otherwise.

**Sweep.** For each strike angle (0°, 30°) and each V₀ of the sweep, one ideal lattice
without walls is struck (V₀ given to bead 0) and the peak speed V_n of every bead of the
0° and +30° observation lines is measured (:mod:`hexdem.peaks`). One run per strike serves
both of its observation lines. The four strike/observation combinations:

=========  ============  ========  ==========  ================================
name       strike, line  start s   law         V_s / V₀
=========  ============  ========  ==========  ================================
``30/30``  30°, +30      1         eq. (v30)   α V₀ + β
``30/0``   30°, 0        2         eq. (v0)    α V₀² + β V₀ + γ
``0/0``    0°, 0         2         eq. (v0)    α V₀² + β V₀ + γ
``0/30``   0°, +30       1         eq. (veq0)  α V₀² + β V₀ + γ
=========  ============  ========  ==========  ================================

**Per-V₀ fit** (:func:`fit_decay`). V_n = V_s c^{n − s} on the window s < n ≤ ``last``, with
V_s the measured peak of the start bead (the paper's "V₁ is the maximum velocity of the
first bead"), so c is the only free parameter. ``kind="loglinear"`` (default) regresses
log(V_n / V_s) on n − s through the origin; ``kind="nonlinear"`` is least squares on V_n
itself (``scipy.optimize.curve_fit``). Both return c and its standard error, which is
conditional on V_s (the measured start bead is taken as exact).

**Laws.** c(V₀) = m V₀ + b and V_s/V₀ = the polynomial above are ordinary least squares
(:func:`polynomial_fit`), with standard errors from the residual variance. Together:
V_n = V₀ (V_s/V₀)(V₀) (m V₀ + b)^{n − s}, eqs. (v30), (v0), (veq0).

**Why c depends on V₀ at all.** The Hertz lattice with linearised bond directions is scale
invariant (x → λx, t → λ^{−1/4}t): c would be a constant. V₀ enters only through the
geometric nonlinearity of the bond lengths |d e + q_j − q_i|, whose relative size grows with
the overlaps δ ∝ V₀^{4/5} (δ ≈ 0.3 d at V₀ = 0.3). So m measures geometric nonlinearity
and b is the law's small-amplitude intercept (c(V₀) is slightly convex over the sweep, so b
lies a little below the measured c at the smallest V₀). The sweep's V₀ = 0.01 … 0.30 are
41 … 1230 m/s for the paper's steel beads; the experiment's 0.4 m/s is V₀ ≈ 1e−4, where the
law gives c = b to 4 digits.

**Physical units** (:meth:`ScalingLaw.physical`): replace every V by V/U, U = d^{5/4}
sqrt(A/M) (end of Sec. V), so m and the V₀-powers of the polynomial pick up powers of 1/U.

**Run design** (:class:`SweepSettings`). The time step is the two-bead Hertz contact time
τ(V₀) over ``steps_per_contact`` and every run lasts ``duration_contacts`` τ(V₀): in units of
τ(V₀) the pulse needs nearly the same time at every V₀ (14.6 τ to peak at bead 12 of the 0°
line). Without walls, the free edges of an uncompressed packing send nothing back (there is
no tension); the hexagon is ``last + 4`` beads per edge so that the line ends stay ahead of
the fitted beads (a larger hexagon gives identical peaks).

**Beyond the paper** (:func:`decay_form_test`). The paper calls the decay a power law but
fits a geometric law in n. Both are two-parameter straight lines, log V_n against n or
against log n, so their residual sums of squares compare directly; the residual curvature
and the drift of the local ratio V_{n+1}/V_n (constant for a geometric law, rising towards 1
as (n/(n+1))^p for a power law) say which one the data follow.
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from multiprocessing import get_context

import numpy as np
from scipy.optimize import curve_fit

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


COMBINATIONS = {c.name: c for c in (
    Combination("30/30", 30.0, "+30", 1, "v30", 1),
    Combination("30/0", 30.0, "0", 2, "v0", 2),
    Combination("0/0", 0.0, "0", 2, "v0", 2),
    Combination("0/30", 0.0, "+30", 1, "veq0", 2),
)}
STRIKES_DEG = (0.0, 30.0)
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
    """Ordinary least squares of y = Σ p_k x^{degree−k} (highest power first, as ``np.polyfit``)."""
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


def fit_decay(n, v, start: int, last: int, kind: str = "loglinear") -> tuple[float, float]:
    """(c, stderr of c) of V_n = V_start c^{n − start} over start < n ≤ last, V_start = v[start]
    (the stderr treats V_start as exact).

    ``n`` bead numbers and ``v`` peak speeds of one line (n ascending from 0).
    """
    if kind not in FIT_KINDS:
        raise HexdemError(f"unknown fit type {kind!r}; use one of: {', '.join(FIT_KINDS)}")
    n, v = np.asarray(n), np.asarray(v, float)
    window = (n > start) & (n <= last)
    if np.count_nonzero(window) < 2:
        raise HexdemError(f"the window {start}..{last} needs at least two beads after the start bead")
    anchor = v[n == start][0]
    k, vk = n[window] - start, v[window]
    if not np.all(np.isfinite(vk)) or not np.isfinite(anchor):
        raise HexdemError(f"peak speeds missing in the window {start}..{last}: the run was too short")
    slope = float(k @ np.log(vk / anchor) / (k @ k))
    residual = np.log(vk / anchor) - slope * k
    slope_err = math.sqrt(residual @ residual / (len(k) - 1) / (k @ k))
    c, c_err = math.exp(slope), math.exp(slope) * slope_err
    if kind == "nonlinear":
        popt, pcov = curve_fit(lambda kk, cc: anchor * cc**kk, k.astype(float), vk, p0=[c])
        c, c_err = float(popt[0]), float(np.sqrt(pcov[0, 0]))
    return c, c_err


@dataclass(frozen=True)
class ScalingLaw:
    """V_n = V₀ P(V₀) (m V₀ + b)^{n − start}: eqs. (v30), (v0), (veq0).

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

    def physical(self, velocity_unit_m_s: float) -> "ScalingLaw":
        """The same law for V₀ and V_n in m/s: every V becomes V/U."""
        u = float(velocity_unit_m_s)
        degree = len(self.amplitude) - 1
        amplitude = tuple(p / u ** (degree - k) for k, p in enumerate(self.amplitude))
        return ScalingLaw(self.combination, self.start, self.m / u, self.b, amplitude, u)


@dataclass(frozen=True)
class CombinationFit:
    """Scaling-law fit of one combination over a V₀ sweep.

    ``v0`` (K,); per V₀: ``c``, ``c_stderr``, ``v_start`` (measured V_s); ``rate`` the fit of
    c = m V₀ + b; ``ratio`` the fit of V_s/V₀ (α, β[, γ]); ``last`` and ``kind`` the window's
    last bead and the per-V₀ fit type.
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
        return ScalingLaw(self.combination.name, self.combination.start, self.rate["m"], self.rate["b"],
                          tuple(self.ratio.values))

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
                "units": "V0, V_n in m/s; m in s/m; alpha in (s/m)^%d; beta in (s/m)^%d" % (degree, degree - 1),
                "velocity_unit_m_s": velocity_unit_m_s,
                "m": physical.m, "b": physical.b,
                **dict(zip(names, list(physical.amplitude) + [None] * (3 - len(physical.amplitude)))),
            },
        }


def _polynomial_text(degree: int) -> str:
    return "alpha V0 + beta" if degree == 1 else "alpha V0^2 + beta V0 + gamma"


def fit_combination(combination: Combination, v0, peaks, last: int = DEFAULT_LAST,
                    kind: str = "loglinear") -> CombinationFit:
    """Fit one combination: ``peaks`` (K, L) peak speeds V_n of its line for each V₀ of ``v0``."""
    v0, peaks = np.asarray(v0, float), np.asarray(peaks, float)
    start = combination.start
    if not start + 2 <= last < peaks.shape[1]:
        raise HexdemError(f"{combination.name}: the window's last bead must lie in {start + 2}..{peaks.shape[1] - 1}, "
                          f"got {last}")
    n = np.arange(peaks.shape[1])
    decay = np.array([fit_decay(n, row, start, last, kind) for row in peaks])
    v_start = peaks[:, start]
    rate = polynomial_fit(v0, decay[:, 0], 1, ("m", "b"))
    ratio = polynomial_fit(v0, v_start / v0, combination.degree, ("alpha", "beta", "gamma")[:combination.degree + 1])
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
            rows.append({"combination": combination.name, "last": last, "fit": kind,
                         "m": fit.rate["m"], "m_stderr": fit.rate.error("m"),
                         "b": fit.rate["b"], "b_stderr": fit.rate.error("b")})
    return rows


# ----------------------------------------------------------- geometric or power law in n

#: Thresholds on the drift fraction φ (see :class:`DecayFormTest`).
GEOMETRIC_BELOW, POWER_ABOVE = 1 / 3, 2 / 3


@dataclass(frozen=True)
class DecayFormTest:
    """Geometric V_n = A qⁿ against power V_n = A n^{−p} on one line at one V₀.

    Both are straight-line fits in log V (against n, against log n) with two parameters:
    ``rss_geometric`` and ``rss_power`` are their residual sums of squares in log V, directly
    comparable. ``q`` and ``p`` the fitted ratio and exponent. The local ratio r_n = V_{n+1}/V_n
    is constant for a geometric law and rises as (n/(n+1))^p for a power law: ``ratio_slope``
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
        """"geometric" or "power" when the residuals and the ratio drift agree, else "neither"."""
        if self.rss_geometric < self.rss_power and self.drift_fraction < GEOMETRIC_BELOW:
            return "geometric"
        if self.rss_power < self.rss_geometric and self.drift_fraction > POWER_ABOVE:
            return "power"
        return "neither"


def decay_form_test(v, start: int, last: int) -> DecayFormTest:
    """Compare the geometric and power forms on beads start … last (start ≥ 1) of one line."""
    if start < 1 or last - start < 3:
        raise HexdemError(f"the form test needs 1 <= start and at least 4 beads, got {start}..{last}")
    v = np.asarray(v, float)
    n = np.arange(start, last + 1).astype(float)
    log_v = np.log(v[start:last + 1])
    geometric = polynomial_fit(n, log_v, 1, ("slope", "intercept"))
    power = polynomial_fit(np.log(n), log_v, 1, ("slope", "intercept"))
    p = -power["slope"]
    drift = polynomial_fit(n[:-1], v[start + 1:last + 1] / v[start:last], 1, ("slope", "intercept"))
    power_drift = polynomial_fit(n[:-1], (n[:-1] / n[1:]) ** p, 1, ("slope", "intercept"))
    return DecayFormTest(geometric.rss, power.rss, math.exp(geometric["slope"]), p,
                         drift["slope"], drift.error("slope"), power_drift["slope"])


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
        "smaller_rss_counts": {"geometric": sum(t.rss_geometric < t.rss_power for t in tests),
                               "power": sum(t.rss_power <= t.rss_geometric for t in tests)},
        "median_drift_fraction": float(np.median([t.drift_fraction for t in tests])),
        "ratio_slope_per_bead": {"at_v0_min": tests[0].ratio_slope, "at_v0_max": tests[-1].ratio_slope,
                                 "v0_min": float(v0[0]), "v0_max": float(v0[-1])},
        "median_rss_power_over_geometric": float(np.median([t.rss_power / t.rss_geometric for t in tests])),
    }


# --------------------------------------------------------------------------- the sweep


@dataclass(frozen=True)
class SweepSettings:
    """How the V₀ sweep is simulated (nondimensional V₀).

    ``v0_min``, ``v0_max``, ``n_v0``: evenly spaced V₀; ``last``: the last bead any fit may
    use; ``edge_beads``: hexagon size (None: ``last`` + 4); ``steps_per_contact``: time step
    τ(V₀)/this; ``samples_per_contact``: output samples per τ(V₀); ``duration_contacts``: run
    length in τ(V₀); ``engine``: "reference" or "lammps"; ``workers``: parallel runs.
    """

    v0_min: float = 0.01
    v0_max: float = 0.30
    n_v0: int = 30
    last: int = DEFAULT_LAST
    edge_beads: int | None = None
    steps_per_contact: int = 140
    samples_per_contact: int = 35
    duration_contacts: float = 16.0
    engine: str = "reference"
    workers: int = 2

    def __post_init__(self):
        if not (0 < self.v0_min < self.v0_max and self.n_v0 >= 4):
            raise HexdemError(f"need 0 < v0_min < v0_max and at least 4 values of V0 (the quadratic laws have "
                              f"3 parameters), got {self.v0_min}..{self.v0_max} with {self.n_v0} values")
        if self.steps_per_contact < self.samples_per_contact or self.samples_per_contact < 5:
            raise HexdemError("need steps_per_contact >= samples_per_contact >= 5")
        if self.workers < 1:
            raise HexdemError(f"workers must be >= 1, got {self.workers}")
        if self.last < 3:
            raise HexdemError(f"the last bead of the windows must be >= 3, got {self.last}")

    @property
    def v0(self) -> np.ndarray:
        return np.round(np.linspace(self.v0_min, self.v0_max, self.n_v0), 12)

    @property
    def hexagon_edge(self) -> int:
        return self.edge_beads if self.edge_beads is not None else self.last + 4

    def config(self, v0: float, strike_deg: float):
        """The :class:`~hexdem.config.RunConfig` of one run of the sweep."""
        from hexdem.config import RunConfig

        base = RunConfig(shape="hexagon", edge_beads=self.hexagon_edge, wall_material="none",
                         units="nondimensional", v0=float(v0), strike_angle_deg=float(strike_deg),
                         engine=self.engine, dump_every=self.steps_per_contact // self.samples_per_contact)
        tau = base.contact_time_s() / base.unit_system.time_s
        return base.replace(dt=tau / self.steps_per_contact, duration=self.duration_contacts * tau)


@dataclass(frozen=True)
class RunPeaks:
    """What one run of the sweep keeps: per observation line (``"0"``, ``"+30"``) the beads'
    ``peaks`` V_n and ``t_peak``, and ``traces`` (times, speeds of the line's beads)."""

    v0: float
    strike_deg: float
    peaks: dict
    t_peak: dict
    traces: dict
    energy_drift: float
    wall_time_s: float


def run_one(settings: SweepSettings, v0: float, strike_deg: float) -> RunPeaks:
    """Simulate one V₀ and strike of the sweep in a scratch directory."""
    from hexdem.experiment import simulate

    start = time.perf_counter()
    config = settings.config(v0, strike_deg)
    with tempfile.TemporaryDirectory(prefix="hexdem-scaling-") as scratch:
        analysis = simulate(config, scratch)
    r, units = analysis.results, analysis.settings.units
    times = analysis.trajectory.times_s / units.time_s
    speeds = analysis.trajectory.speeds_m_s / units.velocity_m_s
    lines = {name: r.lines[name][:settings.last + 2] for name in ("0", "+30")}
    return RunPeaks(float(v0), float(strike_deg),
                    {name: r.peak_speed[beads] for name, beads in lines.items()},
                    {name: r.t_peak[beads] for name, beads in lines.items()},
                    {name: (times, speeds[:, beads]) for name, beads in lines.items()},
                    float(r.energy_drift), time.perf_counter() - start)


@dataclass
class Sweep:
    """Peak speeds of a V₀ sweep: ``runs[(strike_deg, i)]`` the :class:`RunPeaks` of V₀ = v0[i]."""

    settings: SweepSettings
    runs: dict = field(default_factory=dict)
    wall_time_s: float = 0.0

    @property
    def v0(self) -> np.ndarray:
        return self.settings.v0

    def peaks(self, combination: Combination) -> np.ndarray:
        """(K, L) peak speeds V_n along the combination's line for every V₀."""
        rows = [self.runs[(combination.strike_deg, i)].peaks[combination.line] for i in range(len(self.v0))]
        return np.array(rows)

    def fit(self, combination: Combination, last: int | None = None, kind: str = "loglinear") -> CombinationFit:
        peaks = self.peaks(combination)
        last = self.settings.last if last is None else last
        missing = ~np.isfinite(peaks[:, :last + 1])
        if missing.any():
            i, n = np.argwhere(missing)[0]
            raise HexdemError(f"{combination.name}: bead {n} had not peaked at V0 = {self.v0[i]:.4g} within "
                              f"{self.settings.duration_contacts} contact times; raise duration_contacts or "
                              "lower the window's last bead")
        return fit_combination(combination, self.v0, peaks, last, kind)


def run_sweep(settings: SweepSettings, log=None) -> Sweep:
    """All runs of the sweep (both strike angles), ``settings.workers`` at a time, with
    progress on ``log`` (default: stderr)."""
    log = log or (lambda message: print(f"hexdem scaling: {message}", file=sys.stderr, flush=True))
    jobs = [(strike, i, v0) for strike in STRIKES_DEG for i, v0 in enumerate(settings.v0)]
    sweep, start = Sweep(settings), time.perf_counter()
    log(f"{len(jobs)} runs ({settings.engine}, hexagon {settings.hexagon_edge} per edge, no walls, "
        f"{settings.workers} workers)")
    for done, (key, result) in enumerate(_results(settings, jobs), 1):
        sweep.runs[key] = result
        log(f"[{done}/{len(jobs)}] strike {result.strike_deg:g} deg, V0 = {result.v0:.4g}: "
            f"{result.wall_time_s:.1f} s, energy drift {result.energy_drift:.1e}")
    sweep.wall_time_s = time.perf_counter() - start
    return sweep


def _results(settings: SweepSettings, jobs):
    """Yield ((strike, i), RunPeaks) as runs finish: in this process for one worker, else in
    spawned processes (callers' scripts need an ``if __name__ == "__main__":`` guard)."""
    if settings.workers == 1:
        for strike, i, v0 in jobs:
            yield (strike, i), run_one(settings, v0, strike)
        return
    with ProcessPoolExecutor(max_workers=settings.workers, mp_context=get_context("spawn")) as pool:
        futures = {pool.submit(run_one, settings, v0, strike): (strike, i) for strike, i, v0 in jobs}
        for future in as_completed(futures):
            yield futures[future], future.result()


def settings_dict(settings: SweepSettings) -> dict:
    return {**asdict(settings), "hexagon_edge": settings.hexagon_edge}


# --------------------------------------------------------------------------- outputs

#: Files ``write_outputs`` publishes.
OUTPUT_FILES = ("scaling.json", "peaks.csv", "decay_fits.csv", "sensitivity.csv", "decay_form.csv",
                "fig6_vodecay30.png", "fig7_vodecay0.png", "decay_rates.png", "decay_form.png")
#: V₀ of the example traces in Figs. 6a and 7a (the paper's Fig. 6a uses 0.05).
TRACE_V0 = 0.05


def _trace(sweep: Sweep, combination: Combination):
    i = int(np.argmin(abs(sweep.v0 - TRACE_V0)))
    run = sweep.runs[(combination.strike_deg, i)]
    times, speeds = run.traces[combination.line]
    return times, speeds, run.peaks[combination.line], run.t_peak[combination.line], run.v0


def _complete_beads(sweep: Sweep, combination: Combination) -> int:
    """Number of leading beads of the line whose peaks were seen at every V₀."""
    complete = np.all(np.isfinite(sweep.peaks(combination)), axis=0)
    return int(np.argmin(complete)) if not complete.all() else len(complete)


def write_outputs(sweep: Sweep, out, last: int | None = None, kind: str = "loglinear") -> dict:
    """Fit all four combinations and publish :data:`OUTPUT_FILES` in ``out``; returns the
    contents of ``scaling.json``."""
    from hexdem import theory_plots
    from hexdem.config import RunConfig
    from hexdem.io import ensure_writable_dir, write_csv, write_json

    out = ensure_writable_dir(out)
    last = sweep.settings.last if last is None else last
    unit = RunConfig(units="nondimensional").unit_system.velocity_m_s
    fits = {name: sweep.fit(combination, last, kind) for name, combination in COMBINATIONS.items()}
    forms = {name: [decay_form_test(row, c.start, last) for row in sweep.peaks(c)]
             for name, c in COMBINATIONS.items()}
    summary = {name: fit.summary(unit) for name, fit in fits.items()}
    for name, tests in forms.items():
        summary[name]["decay_form"] = decay_form_summary(tests, sweep.v0)
    summary["sweep"] = {**settings_dict(sweep.settings), "v0": sweep.v0.tolist(), "wall_time_s": sweep.wall_time_s,
                        "max_energy_drift": max(run.energy_drift for run in sweep.runs.values()),
                        "velocity_unit_m_s": unit}
    write_json(out / "scaling.json", summary)

    peak_rows = [(run.strike_deg, line, run.v0, n, float(v), float(t))
                 for run in sorted(sweep.runs.values(), key=lambda r: (r.strike_deg, r.v0))
                 for line in ("0", "+30") for n, (v, t) in enumerate(zip(run.peaks[line], run.t_peak[line]))]
    write_csv(out / "peaks.csv", ("strike_deg", "line", "v0", "n", "peak_speed", "t_peak"), peak_rows)
    write_csv(out / "decay_fits.csv",
              ("combination", "v0", "c", "c_stderr", "v_start", "v_start_over_v0", "c_law", "v_start_over_v0_law"),
              [(name, v, c, e, vs, vs / v, float(f.law.decay_rate(v)), float(f.law.start_ratio(v)))
               for name, f in fits.items() for v, c, e, vs in zip(f.v0, f.c, f.c_stderr, f.v_start)])
    sensitivity_rows = [row for c in COMBINATIONS.values()
                        for row in sensitivity(c, sweep.v0, sweep.peaks(c), range(c.start + 2, _complete_beads(sweep, c)))]
    write_csv(out / "sensitivity.csv", tuple(sensitivity_rows[0]), [tuple(r.values()) for r in sensitivity_rows])
    write_csv(out / "decay_form.csv",
              ("combination", "v0", "rss_geometric", "rss_power", "q", "p", "ratio_slope", "ratio_slope_stderr",
               "power_ratio_slope", "drift_fraction", "verdict"),
              [(name, v, t.rss_geometric, t.rss_power, t.q, t.p, t.ratio_slope, t.ratio_slope_stderr,
                t.power_ratio_slope, t.drift_fraction, t.verdict)
               for name, tests in forms.items() for v, t in zip(sweep.v0, tests)])

    theory_plots.vodecay30(_trace(sweep, COMBINATIONS["30/30"]), fits["30/30"], fits["30/0"],
                           out / "fig6_vodecay30.png")
    theory_plots.vodecay0(_trace(sweep, COMBINATIONS["0/0"]), fits["0/0"], fits["0/30"], out / "fig7_vodecay0.png")
    theory_plots.decay_rates(list(fits.values()), out / "decay_rates.png")
    picks = sorted({0, len(sweep.v0) // 2, len(sweep.v0) - 1})
    theory_plots.decay_form(
        {name: [(sweep.v0[i], np.arange(c.start, last), sweep.peaks(c)[i, c.start + 1:last + 1]
                 / sweep.peaks(c)[i, c.start:last]) for i in picks] for name, c in COMBINATIONS.items()},
        out / "decay_form.png")
    return summary
