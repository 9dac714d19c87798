"""LAMMPS against the reference integrator: one configuration through both engines.

:func:`run_comparison` runs ``config`` once with each engine (each run published as by
``hexdem run``, in ``OUT/lammps`` and ``OUT/reference``), then compares peak speed and
arrival time bead by bead along every observation line of the packing and writes
``compare.csv`` (one row per bead), ``compare.json`` (largest differences, tolerances,
verdict) and ``compare.png``. Values are in the run's units (SI or A = d = M = 1).

The default tolerances follow from the engines' accuracy: the reference's RK4 is within 1e-6 of
the converged answer, so the difference is LAMMPS's own error, :data:`MARGIN` times
:func:`expected_error` at the run's steps per contact N (1.6e-4 in peak at the default N = 140,
elastic). Velocity Verlet's error in the pulse's speed accumulates along its path, so each bead's
arrival tolerance grows with its arrival time t: 9.2e-5 contact times + 5.3e-5 t at N = 140. A
systematic bias of one engine (a stiffness off by 0.3 % moves arrivals by 1.2e-3 t) is many times
larger than that.
"""

from __future__ import annotations

import itertools
import shutil
import textwrap
from dataclasses import dataclass, replace

import numpy as np

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.analysis.plotting import UNIT_LABELS, save, subplots
from hexdem.common.checks import is_number
from hexdem.common.io import ensure_writable_dir, write_csv, write_json
from hexdem.errors import HexdemError
from hexdem.experiments.random_packing import prepare_random_packing
from hexdem.experiments.run import run_experiment
from hexdem.model.config import RunConfig
from hexdem.model.dissipation import damping_coefficient
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.unused_keys import on_engine

ENGINE_NAMES = ("lammps", "reference")
#: Markers of the lines in the figure, in the order of the packing's lines.
LINE_MARKERS = "o^v<>sD"
#: Columns of ``compare.csv``; differences are reference − LAMMPS (relative to LAMMPS for peaks).
#: ``arrival_tolerance`` is the bead's own: the tolerance's floor plus its rate times the bead's arrival.
COMPARE_COLUMNS = (
    "line",
    "n",
    "bead_id",
    "peak_lammps",
    "peak_reference",
    "peak_rel_diff",
    "arrival_lammps",
    "arrival_reference",
    "arrival_diff",
    "arrival_tolerance",
    "checked",
)
PEAK_DIFF, ARRIVAL_DIFF, ARRIVAL_TOLERANCE, CHECKED = (
    COMPARE_COLUMNS.index(key) for key in ("peak_rel_diff", "arrival_diff", "arrival_tolerance", "checked")
)


#: LAMMPS's measured error at N steps per contact time τ, against the converged answer, over the
#: lines' beads above 1 % of V0 (``benchmarks/bench_accuracy.py``, docs/validation/convergence.md): velocity
#: Verlet's peak-speed error is at most 0.77/N² relative (rounded up below). Its arrival-time error
#: grows with the time t the pulse has travelled, as its error in the pulse's speed accumulates:
#: at most (0.43 τ + 0.251 t)/N² (:func:`~hexdem.experiments.convergence.arrival_growth` of a
#: 150-bead chain, whose solitary wave keeps the struck bead's contact time and so the fastest
#: growth), rounded up below (every bead of 2D packings up to a 40 d disc stays within 0.85 of
#: the rounded bound). With Tsuji damping α LAMMPS evaluates the damping force at the half-step velocity, an
#: error of first order: measured at most 1.43 α/N in peak and 2.34 α τ/N in arrival for bead–bead
#: restitutions 0.8 to 0.99 (rounded up to 1.5 and 2.5 below). Bead–wall damping adds about 70
#: times less (1e-5 in peak at N = 140 with a wall restitution of 0.9), well inside the elastic
#: terms' margin, and is left out.
PEAK_ERROR_N2, ARRIVAL_ERROR_N2, ARRIVAL_GROWTH_N2 = 0.8, 0.45, 0.26
#: The peak-speed error on the packings that are not the triangular lattice is larger: at most
#: 4.9/N² (a 7 x 9 square struck at 20° with μ = 0.3, where the struck bead drives its column
#: obliquely) and 4.3/N² (a centered-square crystal's interstitials, squeezed between the large
#: beads), measured as the engines' difference at N = 140, 280 and 560 (second order: 4.6 and 3.6
#: times smaller at each doubling); rounded up.
PLACED_PEAK_ERROR_N2 = 5.0
PEAK_ERROR_ALPHA_N, ARRIVAL_ERROR_ALPHA_N = 1.5, 2.5
#: The default tolerances are this many times LAMMPS's expected error.
MARGIN = 4.0


def expected_error(
    steps_per_contact: float, alpha: float = 0.0, peak_n2: float = PEAK_ERROR_N2
) -> tuple[float, float, float]:
    """LAMMPS's expected (relative peak-speed error, arrival-time error at the impact in contact
    times, growth of the arrival-time error per unit of arrival time) at ``steps_per_contact``
    with Tsuji damping ``alpha`` of the bead–bead contacts; ``peak_n2`` the packing's peak error
    coefficient (:data:`PLACED_PEAK_ERROR_N2` off the triangular lattice)."""
    n = float(steps_per_contact)
    return (
        peak_n2 / n**2 + PEAK_ERROR_ALPHA_N * alpha / n,
        ARRIVAL_ERROR_N2 / n**2 + ARRIVAL_ERROR_ALPHA_N * alpha / n,
        ARRIVAL_GROWTH_N2 / n**2,
    )


@dataclass(frozen=True)
class Tolerances:
    """Required agreement: ``peak_rel`` relative peak speed [-], arrival time ``arrival_s`` [s] plus
    ``arrival_rate`` [-] times the bead's arrival time, on the beads whose peak exceeds
    ``min_peak_fraction`` of V0. ``None`` (the default): :data:`MARGIN` times LAMMPS's
    :func:`expected_error` for the run (:meth:`for_run`); a given ``arrival_s`` without a rate
    stays constant (rate 0)."""

    peak_rel: float | None = None
    arrival_s: float | None = None
    arrival_rate: float | None = None
    min_peak_fraction: float = 0.01

    def __post_init__(self):
        for name in ("peak_rel", "arrival_s", "arrival_rate", "min_peak_fraction"):
            value = getattr(self, name)
            defaulted = value is None and name != "min_peak_fraction"
            if not defaulted and not (is_number(value) and value >= 0):
                raise HexdemError(f"tolerance {name} must be a number >= 0, got {value!r}")

    def for_run(self, model: GranularModel, settings: RunSettings) -> Tolerances:
        """These tolerances with the defaults filled in for ``model`` run with ``settings``."""
        rate = 0.0 if self.arrival_s is not None and self.arrival_rate is None else self.arrival_rate
        if self.peak_rel is not None and self.arrival_s is not None and rate is not None:
            return replace(self, arrival_rate=rate)
        if not settings.contact_time_s > 0:
            raise HexdemError("the default tolerances need the run's contact time; give peak_rel and arrival_s")
        peak, arrival, growth = expected_error(
            settings.contact_time_s / settings.dt_s,
            damping_coefficient(model.restitution),
            PEAK_ERROR_N2 if model.packing.bond_steps else PLACED_PEAK_ERROR_N2,
        )
        peak_rel = MARGIN * peak if self.peak_rel is None else self.peak_rel
        arrival_s = MARGIN * arrival * settings.contact_time_s if self.arrival_s is None else self.arrival_s
        return replace(
            self, peak_rel=peak_rel, arrival_s=arrival_s, arrival_rate=MARGIN * growth if rate is None else rate
        )

    def arrival(self, arrival_time: float) -> float:
        """The arrival tolerance of a bead reached at ``arrival_time`` [s] (filled in: :meth:`for_run`)."""
        return self.arrival_s + self.arrival_rate * arrival_time


@dataclass(frozen=True)
class EngineComparison:
    """Per-bead differences of two analyses of one configuration, in the run's units.

    ``rows`` follow :data:`COMPARE_COLUMNS`; ``max_peak_rel_diff`` and ``max_arrival_diff``
    are over the checked beads (inf when one engine saw a pulse the other did not), and
    ``max_arrival_share`` is the largest of their arrival differences over their own tolerances;
    ``arrival_tolerance`` is ``tolerances.arrival_s``, the tolerance at the impact, in the run's
    time unit.
    """

    rows: list
    max_peak_rel_diff: float
    max_arrival_diff: float
    max_arrival_share: float
    arrival_tolerance: float
    tolerances: Tolerances
    units: str

    @property
    def n_checked(self) -> int:
        return sum(1 for row in self.rows if row[CHECKED])

    @property
    def agree(self) -> bool:
        return self.max_peak_rel_diff <= self.tolerances.peak_rel and self.max_arrival_share <= 1.0

    def verdict(self) -> str:
        """One line: the largest differences against their tolerances."""
        time_label = "µs" if self.units == "si" else "T"
        scale = 1e6 if self.units == "si" else 1.0
        return (
            f"max relative peak difference {self.max_peak_rel_diff:.2g} (tolerance {self.tolerances.peak_rel:g}), "
            f"max arrival difference {self.max_arrival_diff * scale:.2g} {time_label} (tolerance "
            f"{self.arrival_tolerance * scale:.3g} {time_label} + {self.tolerances.arrival_rate:.2g} × arrival "
            f"time; at most {self.max_arrival_share:.2g} of a bead's) over {self.n_checked} beads: "
            + ("engines agree" if self.agree else "engines DISAGREE")
        )


def _difference(lammps: float, reference: float, relative: bool) -> float:
    """reference − lammps (relative to lammps); inf when exactly one of them is NaN, or when a
    relative difference is taken from a LAMMPS value of exactly 0 (a bead that never moved) to
    another; 0 when both are 0."""
    if np.isnan(lammps) and np.isnan(reference):
        return float("nan")
    if np.isnan(lammps) or np.isnan(reference):
        return float("inf")
    if relative and lammps == 0:
        return 0.0 if reference == 0 else float("inf")
    return (reference - lammps) / lammps if relative else reference - lammps


def _share(difference: float, tolerance: float) -> float:
    """|difference| over tolerance (0 for no difference, inf beyond a zero tolerance)."""
    size = abs(difference)
    if size == 0 or np.isnan(size):
        return 0.0
    return size / tolerance if tolerance > 0 else float("inf")


def compare_analyses(
    lammps: ImpactAnalysis, reference: ImpactAnalysis, v0: float, tolerances: Tolerances = Tolerances()
) -> EngineComparison:
    """Compare two analyses of the same model; ``v0`` is the impact speed in the run's units."""
    tolerances = tolerances.for_run(lammps.model, lammps.settings)
    time_s = lammps.settings.units.time_s
    a, b = lammps.results, reference.results
    rows = []
    for name, beads in a.lines.items():
        for n, bead in enumerate(beads):
            pa, pb, ta, tb = (
                float(v) for v in (a.peak_speed[bead], b.peak_speed[bead], a.arrival_time[bead], b.arrival_time[bead])
            )
            checked = bool(np.nanmax([pa, pb, -np.inf]) > tolerances.min_peak_fraction * v0)
            tolerance = tolerances.arrival((tb if np.isnan(ta) else ta) * time_s) / time_s
            rows.append(
                (
                    name,
                    n,
                    int(bead) + 1,
                    pa,
                    pb,
                    _difference(pa, pb, True),
                    ta,
                    tb,
                    _difference(ta, tb, False),
                    tolerance,
                    checked,
                )
            )
    checked = [row for row in rows if row[CHECKED]]
    return EngineComparison(
        rows=rows,
        max_peak_rel_diff=max((abs(row[PEAK_DIFF]) for row in checked), default=0.0),
        max_arrival_diff=max((abs(row[ARRIVAL_DIFF]) for row in checked), default=0.0),
        max_arrival_share=max((_share(row[ARRIVAL_DIFF], row[ARRIVAL_TOLERANCE]) for row in checked), default=0.0),
        arrival_tolerance=tolerances.arrival_s / time_s,
        tolerances=tolerances,
        units=a.units,
    )


def comparison_plot(comparison: EngineComparison, v0: float, path) -> None:
    """Peak speed and arrival time per line from both engines (top), |differences| (bottom, log)."""
    units = UNIT_LABELS[comparison.units]
    scale = units["time_scale"]
    fig, axes = subplots(2, 2, figsize=(11, 7.5), sharex=True)
    lines = dict.fromkeys(row[0] for row in comparison.rows)
    for k, (name, marker) in enumerate(zip(lines, itertools.cycle(LINE_MARKERS))):
        rows = [row for row in comparison.rows if row[0] == name]
        n = np.array([row[1] for row in rows])
        column = {
            key: np.array([row[COMPARE_COLUMNS.index(key)] for row in rows], float) for key in COMPARE_COLUMNS[3:10]
        }
        colour = f"C{k}"
        for engine, style in zip(
            ENGINE_NAMES, ({"marker": marker, "linestyle": "none", "mfc": "none"}, {"linestyle": "-"})
        ):
            label = f"{name}°, {engine}"
            axes[0, 0].semilogy(n, column[f"peak_{engine}"] / v0, color=colour, label=label, **style)
            axes[0, 1].plot(n, column[f"arrival_{engine}"] * scale, color=colour, label=label, **style)
        for ax, key, factor in ((axes[1, 0], "peak_rel_diff", 1.0), (axes[1, 1], "arrival_diff", scale)):
            size = np.abs(column[key]) * factor
            ax.semilogy(n, np.where(size > 0, size, np.nan), color=colour, marker=marker, label=f"{name}°")
        axes[1, 1].semilogy(
            n,
            column["arrival_tolerance"] * scale,
            color=colour,
            linestyle="--",
            linewidth=1,
            label=f"{name}°, tolerance",
        )
    axes[1, 0].axhline(comparison.tolerances.peak_rel, color="grey", linestyle="--", linewidth=1, label="tolerance")
    axes[0, 0].set_ylabel("$V_n / V_0$")
    axes[0, 1].set_ylabel(f"arrival time [{units['time']}]")
    axes[1, 0].set_ylabel("|peak difference| / peak (LAMMPS)")
    axes[1, 1].set_ylabel(f"|arrival difference| [{units['time']}]")
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    for ax in axes[1]:
        ax.set_xlabel("bead n along the line")
    fig.suptitle(textwrap.fill(comparison.verdict(), 150), fontsize=9)
    fig.tight_layout()
    save(fig, path)


def run_comparison(config: RunConfig, out, log=None, tolerances: Tolerances = Tolerances()) -> EngineComparison:
    """Run ``config`` with both engines into ``out`` and write the comparison files. A failure
    removes what this call had written (a random disc's ``preparation``, the first engine's run)."""
    out = ensure_writable_dir(out)
    fresh = [path for path in (out / "preparation", *(out / name for name in ENGINE_NAMES)) if not path.exists()]
    try:
        prepared = prepare_random_packing(config, out / "preparation", log=log)  # one packing for both engines
        analyses = {
            name: run_experiment(on_engine(config, name), out / name, log, prepared=on_engine(prepared, name))
            for name in ENGINE_NAMES
        }
    except BaseException:
        for path in fresh:
            shutil.rmtree(path, ignore_errors=True)
        raise
    v0 = analyses["lammps"].v0  # the fastest impact's, which may not be config.v0
    comparison = compare_analyses(analyses["lammps"], analyses["reference"], v0, tolerances)
    tolerances = comparison.tolerances
    write_csv(out / "compare.csv", COMPARE_COLUMNS, comparison.rows)
    write_json(
        out / "compare.json",
        {
            "config": {key: value for key, value in config.shape_dict().items() if key != "engine"},
            "units": comparison.units,
            "tolerances": {
                "peak_rel": tolerances.peak_rel,
                "arrival": comparison.arrival_tolerance,
                "arrival_s": tolerances.arrival_s,
                "arrival_rate": tolerances.arrival_rate,
                "min_peak_fraction": tolerances.min_peak_fraction,
            },
            "beads_checked": comparison.n_checked,
            "max_peak_rel_diff": comparison.max_peak_rel_diff,
            "max_arrival_diff": comparison.max_arrival_diff,
            "max_arrival_share": comparison.max_arrival_share,
            "agree": comparison.agree,
            "energy_drift": {name: analysis.results.energy_drift for name, analysis in analyses.items()},
            "engine_wall_time_s": {name: analysis.engine.get("wall_time_s") for name, analysis in analyses.items()},
        },
    )
    comparison_plot(comparison, v0, out / "compare.png")
    return comparison
