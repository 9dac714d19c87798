"""``sweep.csv`` and ``sweep.png`` of ``hexdem sweep``, read from the runs' own result files.

One row per run, in the plan's order:

* the varied keys, one column each, headed by the key as given (``regions.0.material``);
* ``run``: the run's directory, relative to the sweep's;
* ``status``: ``done``, ``failed`` (its error is in ``runs/<name>.failed`` and in ``error``) or
  ``missing`` (not run yet); the figures of a run that is not done are empty;
* ``warnings``: the names of the warnings of a finished run
  (:data:`~hexdem.experiments.run.RUN_WARNINGS`, joined by ``;``), empty if none: a run whose
  leading wave had not crossed the packing (``far_wall_not_reached``) has decay figures that
  depend on its duration;
* :data:`SUMMARY_COLUMNS`, the scalar figures of the run's ``summary.json`` (``n_beads`` is its
  ``lattice.n_beads``);
* ``energy_share_<region>``: each material region's share of the energy (kinetic and contact)
  at the end of the run, from its ``energy_regions.csv``; empty where a run has no such region;
* ``decay_exponent_<line>``: the power law :math:`V_n ∝ n^{−p}` fitted to the peak speeds of each
  observation line in ``peaks.csv`` (least squares of log V_n on log n) over the beads
  :data:`DECAY_FIRST_N` ≤ n ≤ N − 2 of a line of N beads: n = 0 and 1 are set by the impact,
  and the last bead meets the far wall; empty with fewer than three beads in that range;
* ``error``: the error of a failed run, in one line.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from hexdem.common.io import write_csv
from hexdem.experiments.sweep_plan import SweepRun

#: Scalar figures of a run's ``summary.json`` in the table, in this order.
SUMMARY_COLUMNS = (
    "n_beads",
    "n_samples",
    "energy_drift",
    "energy_lost",
    "rotational_energy_fraction",
    "far_wall_reached",
    "engine_wall_time_s",
    "wall_time_s",
)
#: The first bead of a line in the decay fit.
DECAY_FIRST_N = 2


def _rows_of(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def final_energy_shares(path: Path) -> dict[str, float]:
    """{region: share of the energy} at the last audited time of an ``energy_regions.csv``."""
    rows = _rows_of(path)
    last = max(float(row["time"]) for row in rows)
    return {row["region"]: float(row["energy_fraction"]) for row in rows if float(row["time"]) == last}


def decay_exponent(n, peak_speed) -> float:
    """p of :math:`V_n ∝ n^{−p}` over DECAY_FIRST_N ≤ n ≤ N − 2 (see the module docstring); NaN if
    fewer than three beads there have a peak."""
    n, v = np.asarray(n, float), np.asarray(peak_speed, float)
    chosen = (n >= DECAY_FIRST_N) & (n <= len(n) - 2) & np.isfinite(v) & (v > 0)
    if np.count_nonzero(chosen) < 3:
        return float("nan")
    slope, _ = np.polyfit(np.log(n[chosen]), np.log(v[chosen]), 1)
    return float(-slope)


def decay_exponents(path: Path) -> dict[str, float]:
    """{line: its decay exponent} from a run's ``peaks.csv``."""
    lines: dict[str, list] = {}
    for row in _rows_of(path):
        lines.setdefault(row["line"], []).append((int(row["n"]), float(row["peak_speed"] or "nan")))
    return {line: decay_exponent(*zip(*sorted(pairs))) for line, pairs in lines.items()}


def _run_figures(directory: Path) -> tuple[dict, dict, dict, list[str]]:
    from hexdem.experiments.run import run_warnings

    summary = json.loads((directory / "summary.json").read_text())
    scalars = {key: summary["lattice"]["n_beads"] if key == "n_beads" else summary[key] for key in SUMMARY_COLUMNS}
    return (
        scalars,
        final_energy_shares(directory / "energy_regions.csv"),
        decay_exponents(directory / "peaks.csv"),
        run_warnings(summary["far_wall_reached"]),
    )


def _first_seen(keys_per_run) -> list[str]:
    seen: dict[str, None] = {}
    for keys in keys_per_run:
        seen.update(dict.fromkeys(keys))
    return list(seen)


def write_table(out: Path, runs: list[SweepRun], variations, states) -> list[tuple]:
    """Write ``out / sweep.csv`` (see the module docstring) from the runs' ``states``, a
    (status, error) each; its rows."""
    empty = (dict.fromkeys(SUMMARY_COLUMNS, ""), {}, {}, [])
    figures = [
        _run_figures(out / "runs" / run.name) if status == "done" else empty for run, (status, _) in zip(runs, states)
    ]
    regions = _first_seen(shares for _, shares, _, _ in figures)
    lines = _first_seen(exponents for _, _, exponents, _ in figures)
    header = (
        *(v.key for v in variations),
        "run",
        "status",
        "warnings",
        *SUMMARY_COLUMNS,
        *(f"energy_share_{r}" for r in regions),
        *(f"decay_exponent_{line}" for line in lines),
        "error",
    )

    def cell(value):
        return "" if value == "" or not np.isfinite(value) else value

    rows = [
        (
            *run.values.values(),
            f"runs/{run.name}",
            status,
            ";".join(warnings),
            *scalars.values(),
            *(shares.get(r, "") for r in regions),
            *(cell(exponents.get(line, "")) for line in lines),
            error,
        )
        for run, (status, error), (scalars, shares, exponents, warnings) in zip(runs, states, figures)
    ]
    write_csv(out / "sweep.csv", header, rows)
    return [header, *rows]


def warned_runs(rows: list[tuple]) -> dict[str, list[str]]:
    """{warning name: the runs (their ``run`` cells) that carry it} of the table ``rows``."""
    header, body = rows[0], rows[1:]
    warned: dict[str, list[str]] = {}
    for row in body:
        cells = dict(zip(header, row))
        for name in filter(None, cells["warnings"].split(";")):
            warned.setdefault(name, []).append(cells["run"])
    return warned


def _energy_panel(ax) -> None:
    """The energy panel's axis: the audit's relative drift on a log scale from the audit's round-off
    floor to above the threshold that fails a run, so that round-off spread over a factor of a
    few reads as the flat line it is, not as a trend."""
    from hexdem.analysis.energy import ROUND_OFF
    from hexdem.experiments.run import MAX_ENERGY_DRIFT

    ax.set_yscale("log")
    ax.set_ylim(ROUND_OFF / 10, MAX_ENERGY_DRIFT * 10)
    ax.axhline(MAX_ENERGY_DRIFT, color="firebrick", ls="--", lw=1, label=f"a run fails above {MAX_ENERGY_DRIFT:g}")
    ax.axhspan(ROUND_OFF / 10, ROUND_OFF, color="0.85", label=f"audit's round-off floor ({ROUND_OFF:g} of E(0))")
    ax.set_ylabel("energy drift max|E(t) − E(0)| / K(0)\n(the audit's, dimensionless)")


def sweep_figure(out: Path, runs: list[SweepRun], variations, rows: list[tuple]) -> None:
    """``out / sweep.png``: one column of panels per varied key, that key along the x axis and,
    one row each, the energy audit's relative drift (``energy_drift``, on a log scale between
    the audit's round-off floor and the threshold that fails a run) and the decay exponent of
    the first observation line; one curve per combination of the other keys (categories, such
    as materials, are spread evenly along the axis). Runs that warned are ringed in red."""
    from hexdem.analysis import plotting as plots

    header, body = rows[0], rows[1:]
    shown = ["energy_drift", *[name for name in header if name.startswith("decay_exponent_")][:1]]
    fig, axes = plots.subplots(
        len(shown),
        len(variations),
        figsize=(4.6 * len(variations), 3.4 * len(shown)),
        squeeze=False,
        layout="constrained",
    )
    table = [dict(zip(header, row)) for row in body]
    warned = warned_runs(rows)
    for j, variation in enumerate(variations):
        numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in variation.values)
        position = {
            text: (value if numeric else i) for i, (value, text) in enumerate(zip(variation.values, variation.texts))
        }
        groups: dict[tuple, list] = {}
        for run, row in zip(runs, table):
            others = tuple((key, value) for key, value in run.values.items() if key != variation.key)
            text = variation.texts[variation.values.index(run.values[variation.key])]
            groups.setdefault(others, []).append((position[text], row))
        for i, name in enumerate(shown):
            ax = axes[i, j]
            if name == "energy_drift":
                _energy_panel(ax)
            else:
                ax.set_ylabel(name.replace("_", " "))

            def value(row, name=name):
                return float(row[name]) if row[name] != "" else np.nan

            for others, points in groups.items():
                ax.plot(
                    [x for x, _ in points],
                    [value(r) for _, r in points],
                    "o-",
                    label=", ".join(f"{key} = {value}" for key, value in others) or None,
                )
            ringed = [(x, value(r)) for points in groups.values() for x, r in points if r["warnings"]]
            if ringed:
                ax.plot(*zip(*ringed), "o", ms=13, mfc="none", mec="red", mew=1.5, label=f"warned: {', '.join(warned)}")
            ax.set_xlabel(variation.key)
            ax.grid(True, alpha=0.3)
            if not numeric:
                ax.set_xticks(range(len(variation.texts)), variation.texts)
            if ax.get_legend_handles_labels()[1]:
                ax.legend(fontsize=7)
    warned_count = sum(bool(row["warnings"]) for row in table)
    fig.suptitle(f"hexdem sweep: {len(runs)} runs" + (f", {warned_count} warned (ringed)" if warned_count else ""))
    plots.save(fig, out / "sweep.png")
