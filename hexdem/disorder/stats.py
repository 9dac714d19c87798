"""Statistics of a finished disorder ensemble (Sec. VI-B; Figs. 8, 9).

Loads every realization's ``result.npz`` and the ideal lattice's (:mod:`hexdem.disorder.ensemble`
runs them) and writes, into the ensemble directory, the tables ``peaks_stats.csv``,
``ideal_peaks.csv``, ``arrival_map.csv``, ``disorder_effect.csv`` (peak speeds over the run)
and ``leading_pulse_effect.csv`` (the leading pulses' amplitudes) and the figures of
:mod:`hexdem.disorder.ensemble_figures`; the summary goes to ``ensemble.json``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexdem.common.io import write_csv
from hexdem.disorder.ensemble import Ensemble, velocity_name
from hexdem.disorder.preparation import STAGES
from hexdem.disorder.prestress import PRESTRESS_ARRAYS
from hexdem.errors import HexdemError
from hexdem.model.packing import Packing

#: Columns of ``peaks_stats.csv`` (a contract).
STATS_COLUMNS = ("v_striker", "line", "n", "mean_peak_speed", "std_peak_speed", "count", "warnings")
IDEAL_COLUMNS = ("v_striker", "line", "n", "peak_speed")
ARRIVAL_COLUMNS = (
    "v_striker",
    "bead_id",
    "m",
    "n",
    "x",
    "y",
    "ideal_relative_arrival",
    "mean_relative_arrival",
    "std_relative_arrival",
    "count",
)
EFFECT_COLUMNS = ("v_striker", "line", "first_n", "last_n", "mean_ratio", "std_ratio", "sem_ratio", "realizations")
#: First bead of the lines entering the disorder-effect ratio (n = 0, 1 are the struck bead
#: and its neighbour, set by the striker rather than by the lattice).
EFFECT_FIRST_N = 2


@dataclass(frozen=True)
class EnsembleResults:
    """Stacked results: ``peak_speed``, ``lead_speed`` (the leading pulse's amplitude, NaN off
    the lines, :mod:`hexdem.analysis.leading_pulse`) and ``arrival_time`` (R, V, N) for R
    realizations, V striker velocities [m/s] and N beads [m/s, s]; ``ideal_*`` the ideal
    lattice's (V, N); ``per_realization`` every other array of the realizations'
    ``result.npz``, stacked."""

    velocities_m_s: np.ndarray
    peak_speed: np.ndarray
    lead_speed: np.ndarray
    arrival_time: np.ndarray
    ideal_peak_speed: np.ndarray
    ideal_lead_speed: np.ndarray
    ideal_arrival_time: np.ndarray
    per_realization: dict

    def speeds(self, measure: str) -> tuple[np.ndarray, np.ndarray]:
        """(disordered (R, V, N), ideal (V, N)) speeds of ``measure``: "peak" or "lead"."""
        if measure == "lead":
            return self.lead_speed, self.ideal_lead_speed
        return self.peak_speed, self.ideal_peak_speed


def _load(path: Path) -> dict:
    with np.load(path) as data:
        return {name: data[name] for name in data.files}


def load_results(ensemble: Ensemble) -> EnsembleResults:
    """Read every realization's ``result.npz`` and the ideal one (all must exist)."""
    config = ensemble.config
    missing = [k for k in range(config.realizations) if not ensemble.result_path(k).exists()]
    if missing or not ensemble.result_path(None).exists():
        raise HexdemError(
            f"{ensemble.out}: {len(missing)} realization(s) unfinished; rerun hexdem ensemble to complete it"
        )
    runs = [_load(ensemble.result_path(k)) for k in range(config.realizations)]
    ideal = _load(ensemble.result_path(None))
    stacked = ("peak_speed", "lead_speed", "arrival_time")
    return EnsembleResults(
        velocities_m_s=ideal["velocities_m_s"],
        **{name: np.array([r[name] for r in runs]) for name in stacked},
        **{f"ideal_{name}": ideal[name] for name in stacked},
        per_realization={key: np.array([r[key] for r in runs]) for key in runs[0] if key not in (*stacked, "t_peak")}
        | {
            "ideal_energy_drift": ideal["energy_drift"],
            "ideal_lammps_s": ideal["impact_lammps_s"],
            "ideal_far_wall_reached": ideal["far_wall_reached"],
        },
    )


def _mean_std_count(values: np.ndarray, axis: int = 0):
    count = np.sum(np.isfinite(values), axis=axis)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.nansum(values, axis=axis) / count
        deviation = np.where(np.isfinite(values), values - np.expand_dims(mean, axis), 0.0)
        std = np.sqrt(np.sum(deviation**2, axis=axis) / (count - 1))
    mean = np.where(count > 0, mean, np.nan)
    std = np.where(count > 1, std, np.nan)
    return mean, std, count


def mean_and_sem(values) -> tuple[float, float]:
    """(mean, standard error of the mean) of the finite ``values`` (1D); no error from fewer than two."""
    mean, std, count = _mean_std_count(np.asarray(values, float))
    return float(mean), float(std / np.sqrt(count)) if count > 1 else float("nan")


def impact_warnings(results: EnsembleResults) -> list[str]:
    """Per striker velocity, the warnings of its impacts (:data:`~hexdem.experiments.run.RUN_WARNINGS`),
    each with the impacts that carry it (``ideal``, realizations as their folders ``r0003``), e.g.
    ``far_wall_not_reached (ideal, r0000, r0003)``; empty where none warned."""
    from hexdem.experiments.run import run_warnings

    everyone = [
        ("ideal", results.per_realization["ideal_far_wall_reached"]),
        *((f"r{k:04d}", row) for k, row in enumerate(results.per_realization["far_wall_reached"])),
    ]
    cells = []
    for iv in range(len(results.velocities_m_s)):
        warned: dict[str, list[str]] = {}
        for who, reached in everyone:
            for name in run_warnings(bool(reached[iv])):
                warned.setdefault(name, []).append(who)
        cells.append("; ".join(f"{name} ({', '.join(who)})" for name, who in warned.items()))
    return cells


def peak_statistics(results: EnsembleResults, lattice: Packing) -> list[tuple]:
    """Rows of ``peaks_stats.csv``: mean and sample standard deviation over realizations of
    the peak speed of bead n of each line, for each striker velocity, with the warnings of that
    velocity's impacts (:func:`impact_warnings`): a wave cut short before it crossed the packing
    has peaks that depend on the run's duration."""
    mean, std, count = _mean_std_count(results.peak_speed)
    warnings = impact_warnings(results)
    return [
        (float(v), line, n, float(mean[iv, bead]), float(std[iv, bead]), int(count[iv, bead]), warnings[iv])
        for iv, v in enumerate(results.velocities_m_s)
        for line, beads in lattice.lines().items()
        for n, bead in enumerate(beads)
    ]


def ideal_peaks(results: EnsembleResults, lattice: Packing) -> list[tuple]:
    return [
        (float(v), line, n, float(results.ideal_peak_speed[iv, bead]))
        for iv, v in enumerate(results.velocities_m_s)
        for line, beads in lattice.lines().items()
        for n, bead in enumerate(beads)
    ]


def relative_arrivals(results: EnsembleResults, reference: int):
    """Arrival times relative to bead ``reference``: ideal (V, N) and per realization (R, V, N)."""
    return (
        results.ideal_arrival_time - results.ideal_arrival_time[:, [reference]],
        results.arrival_time - results.arrival_time[:, :, [reference]],
    )


def arrival_rows(results: EnsembleResults, lattice: Packing, reference: int) -> list[tuple]:
    ideal, disordered = relative_arrivals(results, reference)
    mean, std, count = _mean_std_count(disordered)
    return [
        (
            float(v),
            bead + 1,
            int(m),
            int(n),
            float(x),
            float(y),
            float(ideal[iv, bead]),
            float(mean[iv, bead]),
            float(std[iv, bead]),
            int(count[iv, bead]),
        )
        for iv, v in enumerate(results.velocities_m_s)
        for bead, ((m, n), (x, y)) in enumerate(zip(lattice.labels, lattice.positions_m))
    ]


def mirror_lines(lines) -> list[tuple[str, str]]:
    """(``"+a"``, ``"-a"``) for every pair of lines mirrored about the 0° strike: the hexagon's ±30°,
    a square's ±45° and ±90°."""
    return [(name, "-" + name[1:]) for name in lines if name.startswith("+") and "-" + name[1:] in lines]


def disorder_effect(results: EnsembleResults, lattice: Packing, measure: str = "peak") -> list[tuple]:
    """Transmission along each line, disordered / ideal (the paper's claim of Sec. VI-B).

    For each realization, the ratio V_n / V_n(ideal) averaged over beads n ≥ 2 of the line
    whose ideal speed was seen (a square's beads off the struck row stay at rest); then the mean, sample standard
    deviation and standard error
    over realizations. "±30" pools both 30° lines of each realization (on a square, "±45" and "±90"
    pool its mirrored rays). ``measure``: V_n is the
    peak speed over the run ("peak") or the leading pulse's amplitude ("lead").
    """
    rows = []
    lines = lattice.lines()
    speeds, ideal_speeds = results.speeds(measure)
    for iv, v in enumerate(results.velocities_m_s):
        ratios = {}
        for line, beads in lines.items():
            beads = beads[EFFECT_FIRST_N:]
            beads = beads[np.isfinite(ideal_speeds[iv, beads]) & (ideal_speeds[iv, beads] > 0)]
            with np.errstate(invalid="ignore"):
                ratios[line] = (speeds[:, iv, beads] / ideal_speeds[iv, beads], beads)
        for plus, minus in mirror_lines(lines):
            longer = max(ratios[plus][1], ratios[minus][1], key=len)
            ratios[f"±{plus[1:]}"] = (np.concatenate([ratios[plus][0], ratios[minus][0]], axis=1), longer)
        for line, (ratio, beads) in ratios.items():
            per_realization = np.nanmean(ratio, axis=1) if ratio.shape[1] else np.full(len(ratio), np.nan)
            mean, std, count = _mean_std_count(per_realization)
            last_n = EFFECT_FIRST_N + len(beads) - 1
            rows.append(
                (
                    float(v),
                    line,
                    EFFECT_FIRST_N,
                    int(last_n),
                    float(mean),
                    float(std),
                    float(std / np.sqrt(count)) if count > 1 else float("nan"),
                    int(count),
                )
            )
    return rows


def write_statistics(ensemble: Ensemble, laws: dict | None = None) -> dict:
    """Write the tables and figures of a finished ensemble; returns the summary for ensemble.json.

    Tables: ``peaks_stats.csv``, ``ideal_peaks.csv``, ``arrival_map.csv`` (relative to the
    reference bead), ``disorder_effect.csv``, ``leading_pulse_effect.csv``. Figures: ``fig9_all_directions.png`` (with
    the
    fitted ``laws`` {line: ScalingLaw} if any) and ``fig8_expnumsim_v<V>.png`` per velocity.
    """
    from hexdem.disorder import ensemble_figures as ensemble_plots

    config, lattice, out = ensemble.config, ensemble.ideal, ensemble.out
    results = load_results(ensemble)
    reference = lattice.index_of(*config.reference_bead)
    stats, ideal = peak_statistics(results, lattice), ideal_peaks(results, lattice)
    effect, lead_effect = disorder_effect(results, lattice), disorder_effect(results, lattice, "lead")
    write_csv(out / "peaks_stats.csv", STATS_COLUMNS, stats)
    write_csv(out / "ideal_peaks.csv", IDEAL_COLUMNS, ideal)
    write_csv(out / "arrival_map.csv", ARRIVAL_COLUMNS, arrival_rows(results, lattice, reference))
    write_csv(out / "disorder_effect.csv", EFFECT_COLUMNS, effect)
    write_csv(out / "leading_pulse_effect.csv", EFFECT_COLUMNS, lead_effect)
    ensemble_plots.all_directions(
        stats, ideal, laws or {}, out / "fig9_all_directions.png", ensemble_plots.fig9_lines(lattice)
    )
    ideal_rel, disordered_rel = relative_arrivals(results, reference)
    for iv, v in enumerate(results.velocities_m_s):
        mean, _, _ = _mean_std_count(disordered_rel[:, iv])
        ensemble_plots.expnumsim(
            lattice,
            ensemble.impact_model(None, v).walls,
            ideal_rel[iv],
            mean,
            reference,
            float(v),
            config.realizations,
            out / f"fig8_expnumsim_{velocity_name(v)}.png",
        )
    per = results.per_realization
    effect_beads = np.concatenate([beads[EFFECT_FIRST_N:] for beads in lattice.lines().values()])
    return {
        "disorder_effect": [dict(zip(EFFECT_COLUMNS, row)) for row in effect],
        "leading_pulse_effect": [dict(zip(EFFECT_COLUMNS, row)) for row in lead_effect],
        "leading_pulse_defined_fraction": float(np.mean(np.isfinite(results.lead_speed[:, :, effect_beads]))),
        "prestress": {
            name: {
                "mean": float(np.mean(per[name])),
                "std": float(np.std(per[name], ddof=1)) if len(per[name]) > 1 else float("nan"),
            }
            for name in PRESTRESS_ARRAYS
        },
        "preparation": {
            stage: {
                "mean_steps": float(np.mean(per[f"{stage}_steps"])),
                "max_steps": int(np.max(per[f"{stage}_steps"])),
                "mean_simulated_time_s": float(np.mean(per[f"{stage}_time_s"])),
                "max_kinetic_energy_j": float(np.max(per[f"{stage}_kinetic_energy_j"])),
                "max_force_n": float(np.max(per[f"{stage}_max_force_n"])),
            }
            for stage in STAGES
        }
        | {"max_overlap_m": float(np.max(per["max_overlap_m"]))},
        "lammps_time_s": {
            "settle_per_realization": float(np.mean(per["compact_lammps_s"] + per["settle_lammps_s"])),
            "impact_per_run": float(np.mean(per["impact_lammps_s"])),
            "settle_total": float(np.sum(per["compact_lammps_s"] + per["settle_lammps_s"])),
            "impact_total": float(np.sum(per["impact_lammps_s"]) + np.sum(per["ideal_lammps_s"])),
        },
        "energy_drift_max": {
            "disordered": float(np.max(per["energy_drift"])),
            "ideal": float(np.max(per["ideal_energy_drift"])),
        },
        "far_wall_reached_fraction": float(np.mean(per["far_wall_reached"])),
        "impact_warnings": impact_warnings(results),
    }
