"""The files of ``hexdem scaling``: the four laws fitted to a V₀ sweep, as tables and figures.

:func:`write_outputs` fits every combination of :mod:`hexdem.theory.scaling` to a
:class:`~hexdem.theory.sweep.Sweep` and publishes ``scaling.json``, the CSV tables and the PNGs of
Figs. 6 and 7 (:mod:`hexdem.theory.theory_figures`).
"""

from __future__ import annotations

import numpy as np

from hexdem.theory.scaling import COMBINATIONS, Combination, decay_form_summary, decay_form_test, sensitivity
from hexdem.theory.sweep import Sweep

#: Files ``write_outputs`` publishes.
OUTPUT_FILES = (
    "scaling.json",
    "peaks.csv",
    "decay_fits.csv",
    "sensitivity.csv",
    "decay_form.csv",
    "fig6_vodecay30.png",
    "fig7_vodecay0.png",
    "decay_rates.png",
    "decay_form.png",
)
#: V₀ of the example traces in Figs. 6a and 7a (the paper's Fig. 6a uses 0.05).
TRACE_V0 = 0.05


def _trace(sweep: Sweep, combination: Combination):
    i = int(np.argmin(abs(sweep.v0 - TRACE_V0)))
    run = sweep.runs[(combination.strike_deg, i)]
    times, speeds = run.traces[combination.line]
    return times, speeds, run.peaks[combination.line], run.t_peak[combination.line], run.v0


def complete_beads(peaks) -> int:
    """Number of leading beads of a line whose peaks ``peaks`` (K, L) were seen at every V₀."""
    complete = np.all(np.isfinite(peaks), axis=0)
    return int(np.argmin(complete)) if not complete.all() else len(complete)


def read_sweep_peaks(out) -> tuple[np.ndarray, dict]:
    """(V₀ (K,), {combination: peak speeds (K, L)}) from the ``peaks.csv`` of a finished
    ``hexdem scaling`` in ``out``: the sweep again, for new fits without new runs."""
    import csv
    from pathlib import Path

    from hexdem.errors import HexdemError

    path = Path(out) / "peaks.csv"
    try:
        with open(path, newline="") as fh:
            rows = [
                (float(r["strike_deg"]), r["line"], float(r["v0"]), int(r["n"]), float(r["peak_speed"]))
                for r in csv.DictReader(fh)
            ]
    except (OSError, KeyError, ValueError):
        raise HexdemError(f"{path} is missing or is not the peaks.csv of hexdem scaling") from None
    v0 = np.array(sorted({r[2] for r in rows}))
    beads = max(r[3] for r in rows) + 1
    table = {(strike, line): np.full((len(v0), beads), np.nan) for strike, line, *_ in rows}
    for strike, line, v, n, peak in rows:
        table[(strike, line)][np.searchsorted(v0, v), n] = peak
    return v0, {name: table[(c.strike_deg, c.line)] for name, c in COMBINATIONS.items()}


def write_outputs(sweep: Sweep, out, last: int | None = None, kind: str = "loglinear") -> dict:
    """Fit all four combinations and publish :data:`OUTPUT_FILES` in ``out``; returns the
    contents of ``scaling.json``."""
    from hexdem.common.io import ensure_writable_dir, write_csv, write_json
    from hexdem.model.config import RunConfig
    from hexdem.theory import theory_figures as theory_plots

    out = ensure_writable_dir(out)
    last = sweep.settings.last if last is None else last
    unit = RunConfig(units="nondimensional").unit_system.velocity_m_s
    fits = {name: sweep.fit(combination, last, kind) for name, combination in COMBINATIONS.items()}
    forms = {name: [decay_form_test(row, c.start, last) for row in sweep.peaks(c)] for name, c in COMBINATIONS.items()}
    summary = {name: fit.summary(unit) for name, fit in fits.items()}
    for name, tests in forms.items():
        summary[name]["decay_form"] = decay_form_summary(tests, sweep.v0)
    summary["sweep"] = {
        **sweep.settings.as_dict(),
        "v0": sweep.v0.tolist(),
        "wall_time_s": sweep.wall_time_s,
        "max_energy_drift": max(run.energy_drift for run in sweep.runs.values()),
        "velocity_unit_m_s": unit,
        "runs_that_warned": [
            {"strike_deg": run.strike_deg, "v0": run.v0, "warnings": list(run.warnings)}
            for run in sweep.runs.values()
            if run.warnings
        ],
    }
    write_json(out / "scaling.json", summary)

    peak_rows = [
        (run.strike_deg, line, run.v0, n, float(v), float(t), " ".join(run.warnings))
        for run in sorted(sweep.runs.values(), key=lambda r: (r.strike_deg, r.v0))
        for line in ("0", "+30")
        for n, (v, t) in enumerate(zip(run.peaks[line], run.t_peak[line]))
    ]
    write_csv(out / "peaks.csv", ("strike_deg", "line", "v0", "n", "peak_speed", "t_peak", "warnings"), peak_rows)

    write_csv(
        out / "decay_fits.csv",
        ("combination", "v0", "c", "c_stderr", "v_start", "v_start_over_v0", "c_law", "v_start_over_v0_law"),
        [
            (name, v, c, e, vs, vs / v, float(f.law.decay_rate(v)), float(f.law.start_ratio(v)))
            for name, f in fits.items()
            for v, c, e, vs in zip(f.v0, f.c, f.c_stderr, f.v_start)
        ],
    )
    sensitivity_rows = [
        row
        for c in COMBINATIONS.values()
        for row in sensitivity(c, sweep.v0, sweep.peaks(c), range(c.start + 2, complete_beads(sweep.peaks(c))))
    ]
    write_csv(out / "sensitivity.csv", tuple(sensitivity_rows[0]), [tuple(r.values()) for r in sensitivity_rows])
    write_csv(
        out / "decay_form.csv",
        (
            "combination",
            "v0",
            "rss_geometric",
            "rss_power",
            "q",
            "p",
            "ratio_slope",
            "ratio_slope_stderr",
            "power_ratio_slope",
            "drift_fraction",
            "verdict",
        ),
        [
            (
                name,
                v,
                t.rss_geometric,
                t.rss_power,
                t.q,
                t.p,
                t.ratio_slope,
                t.ratio_slope_stderr,
                t.power_ratio_slope,
                t.drift_fraction,
                t.verdict,
            )
            for name, tests in forms.items()
            for v, t in zip(sweep.v0, tests)
        ],
    )

    theory_plots.vodecay30(
        _trace(sweep, COMBINATIONS["30/30"]), fits["30/30"], fits["30/0"], out / "fig6_vodecay30.png"
    )
    theory_plots.vodecay0(_trace(sweep, COMBINATIONS["0/0"]), fits["0/0"], fits["0/30"], out / "fig7_vodecay0.png")
    theory_plots.decay_rates(list(fits.values()), out / "decay_rates.png")
    picks = sorted({0, len(sweep.v0) // 2, len(sweep.v0) - 1})
    theory_plots.decay_form(
        {
            name: [
                (
                    sweep.v0[i],
                    np.arange(c.start, last),
                    sweep.peaks(c)[i, c.start + 1 : last + 1] / sweep.peaks(c)[i, c.start : last],
                )
                for i in picks
            ]
            for name, c in COMBINATIONS.items()
        },
        out / "decay_form.png",
    )
    return summary
