"""``hexdem paper``: every part of the paper, resumable, behind one progress display.

The parts, each writing into its own folder of ``DIR``:

=====================  =====================================================================
``tca/``               ω, c and Fig. 5 (both lattices simulated)
``fig3/``, ``fig4/``   wavefront snapshots, Figs. 3 and 4 (Fig. 4 on ``workers`` MPI ranks)
``scaling/``           the V₀ sweep and the four laws, Figs. 6 and 7
``fit_protocols/``     the fit-protocol search on that sweep
``disorder/<name>/``   the ensembles of the disorder study and of the crossover sweep;
                       ``sigma6tol`` holds Figs. 8 and 9
``disorder/``          the study's tables, figure and verdict; the crossover sweep's
                       ``disorder_crossover.csv``, ``.json``, ``.png`` and
                       ``disorder_crossover_overlap.png``
``friction/<name>/``   the σ = 6 tol ensemble struck with friction μ, on the paper's packings
``friction/``          the friction study (:mod:`hexdem.paper.friction_study`):
                       ``friction_effect.csv``, ``friction_decay.csv``, ``friction_effect.png``,
                       ``friction_study.json``
=====================  =====================================================================

then ``report.html``, ``report.md`` and ``published_vs_computed.csv`` (:mod:`hexdem.paper.report`).

**Resuming.** A finished part leaves ``DIR/parts/<name>.json`` (its summary, written
atomically last); a rerun skips every part that has one, unless a part whose results it
reads was computed again, and the ensembles resume realization by realization. ``DIR/paper.json`` records the settings:
a rerun with others
(``--quick`` or not) is refused rather than mixed, and ``DIR/.lock`` refuses a second
``hexdem paper`` while one runs.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from hexdem.common.io import ensure_writable_dir, locked_directory, write_json
from hexdem.common.progress import progress_bar, silenced
from hexdem.errors import HexdemError
from hexdem.experiments.executors import holding, parsl_session
from hexdem.paper.disorder_study import (
    FIGURES_ENSEMBLE,
    prestress_rows,
    run_study_ensemble,
    study_ensembles,
    study_figure,
    study_rows,
    verdict,
)
from hexdem.paper.friction_study import friction_name, run_friction_ensemble
from hexdem.paper.settings import PaperSettings

SETTINGS_NAME = "paper.json"
#: Snapshot times of Fig. 4 on the quick run's smaller half-hexagon [ms].
QUICK_FIG4_TIMES_MS = (0.2, 0.4, 0.6, 0.8, 1.0, 1.2)


def _tca(out: Path) -> dict:
    from hexdem.theory import tca
    from hexdem.theory.tca_lattice import write_fig5

    result = {**tca.summary(), "lattice": write_fig5(ensure_writable_dir(out / "tca"), "reference", _quiet)}
    write_json(out / "tca" / "tca.json", result)
    return result


def _snapshots(settings: PaperSettings, out: Path, shape: str) -> dict:
    from hexdem.experiments.snapshots import DEFAULT_TIMES_MS, run_snapshots
    from hexdem.model.config import RunConfig

    long_edge, short_edge = settings.half_hexagon
    half = shape == "half-hexagon"
    edges = {"long_edge": long_edge, "short_edge": short_edge} if half else {}  # (a hexagon refuses them)
    config = RunConfig(
        shape=shape,
        **edges,
        impact="striker",
        v0=0.4,
        ranks=settings.workers if half else 1,
        launcher=settings.launcher,
        steps_per_contact=settings.steps_per_contact,
    )
    times_ms = QUICK_FIG4_TIMES_MS if half and settings.quick else DEFAULT_TIMES_MS[shape]
    folder = out / ("fig4" if half else "fig3")
    run_snapshots(config, [t * 1e-3 for t in times_ms], folder, outline_edge=11 if half else None, log=_quiet)
    return json.loads((folder / "snapshots.json").read_text())


def _scaling(settings: PaperSettings, out: Path, parsl) -> dict:
    from hexdem.theory.outputs import write_outputs
    from hexdem.theory.sweep import SweepSettings, run_sweep

    sweep = run_sweep(
        SweepSettings(n_v0=settings.n_v0, workers=settings.workers, launcher=settings.launcher, parsl=settings.parsl),
        log=_quiet,
        parsl=parsl,
    )
    return write_outputs(sweep, out / "scaling")


def _fit_protocols(out: Path) -> dict:
    from hexdem.paper.fit_protocols import run_search

    return run_search(out / "scaling", ensure_writable_dir(out / "fit_protocols"))


def _disorder_summary(summaries: list[dict], out: Path) -> dict:
    from hexdem.common.io import write_csv
    from hexdem.paper.disorder_study import PRESTRESS_COLUMNS, STUDY_COLUMNS

    rows, loads = study_rows(summaries), prestress_rows(summaries)
    folder = out / "disorder"
    write_csv(folder / "disorder_study.csv", STUDY_COLUMNS, rows)
    write_csv(folder / "prestress.csv", PRESTRESS_COLUMNS, loads)
    study_figure(rows, folder / "disorder_study.png")
    result = {
        "rows": [dict(zip(STUDY_COLUMNS, row)) for row in rows],
        "verdict": verdict(rows),
        "prestress": [dict(zip(PRESTRESS_COLUMNS, row)) for row in loads],
        "figures_ensemble": FIGURES_ENSEMBLE,
        "leading_pulse_defined_fraction": {s["name"]: s["leading_pulse_defined_fraction"] for s in summaries},
    }
    write_json(folder / "disorder_study.json", result)
    return result


def _crossover(summaries: list[dict], out: Path) -> dict:
    from hexdem.common.io import write_csv
    from hexdem.paper.crossover import (
        CROSSOVER_COLUMNS,
        CROSSOVER_FIGURES,
        crossover_figure,
        crossover_fits,
        crossover_rows,
        crossover_verdict,
        overlap_test,
        pm30_claim,
    )

    rows = crossover_rows(summaries)
    fits = crossover_fits(rows)
    tests = overlap_test(fits)
    folder = out / "disorder"
    write_csv(folder / "disorder_crossover.csv", CROSSOVER_COLUMNS, rows)
    for against, name in CROSSOVER_FIGURES.items():
        crossover_figure(rows, fits, folder / name, against)
    result = {
        "fits": fits,
        "overlap_test": tests,
        "verdict": crossover_verdict(fits, tests),
        "pm30_claim": pm30_claim(rows),
        "sigma_per_tol": sorted({r[3] for r in rows}),
        "velocities_m_s": sorted({r[0] for r in rows}),
    }
    write_json(folder / "disorder_crossover.json", result)
    return result


def _friction_summary(settings: PaperSettings, summaries: dict, out: Path) -> dict:
    from hexdem.common.io import write_csv
    from hexdem.paper.friction_figure import friction_figure
    from hexdem.paper.friction_study import (
        DECAY_COLUMNS,
        EFFECT_COLUMNS,
        arrival_verdict,
        disorder_verdict,
        friction_tables,
    )

    rows, decay, conditions = friction_tables(out, settings, summaries)
    folder = out / "friction"
    write_csv(folder / "friction_effect.csv", EFFECT_COLUMNS, rows)
    write_csv(folder / "friction_decay.csv", DECAY_COLUMNS, decay)
    friction_figure(rows, decay, conditions, settings.ensemble_edge_beads, folder / "friction_effect.png")
    result = {
        "rows": [dict(zip(EFFECT_COLUMNS, row)) for row in rows],
        "decay": [dict(zip(DECAY_COLUMNS, row)) for row in decay],
        "disorder": conditions,
        "realizations": settings.friction_realizations,
        "paper_realizations": settings.realizations,
        "arrival_verdict": arrival_verdict(rows),
        "disorder_verdict": disorder_verdict(conditions),
    }
    write_json(folder / "friction_study.json", result)
    return result


def _quiet(message: str) -> None:
    """The parts' own logs: the paper's progress display replaces them."""


def _check_settings(out: Path, settings: PaperSettings) -> None:
    path = out / SETTINGS_NAME
    if path.exists():
        try:
            previous = json.loads(path.read_text())["identity"]
        except (OSError, ValueError, KeyError, TypeError):
            raise HexdemError(
                f"{path} is unreadable: {out} does not hold a hexdem paper run; choose another --out"
            ) from None
        if previous != settings.identity():
            raise HexdemError(
                f"{out} holds a hexdem paper run with other settings ({previous}); "
                "rerun with the same ones to resume it, or choose another --out"
            )
    write_json(path, {"identity": settings.identity(), "settings": settings.as_dict()})


def run_paper(settings: PaperSettings, out, log=None) -> dict:
    """Run (or resume) every part into ``out`` and write the report; returns the parts' summaries.
    The ``settings.parsl`` file runs once, and its Parsl takes the runs of every study."""
    log = log or (lambda message: print(f"hexdem paper: {message}", file=sys.stderr, flush=True))
    parsl = parsl_session(settings.parsl, out)
    out = ensure_writable_dir(out)
    with locked_directory(out, "another hexdem paper"), holding(parsl, settings.workers):
        _check_settings(out, settings)
        summaries, wall_time_s = _run_parts(settings, out, parsl)
    log(f"report in {out / 'report.html'} ({wall_time_s:.0f} s)")
    return summaries


def _run_parts(settings: PaperSettings, out: Path, parsl) -> tuple[dict, float]:
    """Every part in order (skipping the finished ones), then the report; (summaries, wall time [s]).
    ``parsl``: the :class:`~hexdem.experiments.executors.ParslSession` of ``settings.parsl``."""
    from hexdem.paper.report import write_report

    scaling_json = out / "scaling" / "scaling.json"
    ensembles = study_ensembles(settings)
    ensemble_parts = [f"disorder-{e.name}" for e in ensembles]
    # (name, label, the parts whose results it reads, work)
    parts = [
        ("tca", "TCA and Fig. 5", (), lambda: _tca(out)),
        ("fig3", "Fig. 3 snapshots", (), lambda: _snapshots(settings, out, "hexagon")),
        ("fig4", "Fig. 4 snapshots", (), lambda: _snapshots(settings, out, "half-hexagon")),
        (
            "scaling",
            f"V0 sweep ({settings.n_v0} values) and laws, Figs. 6-7",
            (),
            lambda: _scaling(settings, out, parsl),
        ),
        ("fit_protocols", "fit-protocol search", ("scaling",), lambda: _fit_protocols(out)),
    ]
    parts += [
        (
            name,
            f"ensemble {e.name}",
            ("scaling",),
            lambda e=e: run_study_ensemble(e, settings, parsl, out / "disorder", scaling_json, ensembles),
        )
        for name, e in zip(ensemble_parts, ensembles)
    ]
    study_parts = [name for name, e in zip(ensemble_parts, ensembles) if e.sigma_per_tol in settings.sigma_per_tol]
    parts.append(
        (
            "disorder",
            "disorder study and verdict",
            tuple(study_parts),
            lambda: _disorder_summary([summaries[name] for name in study_parts], out),
        )
    )
    parts.append(
        (
            "crossover",
            "disorder crossover sweep",
            tuple(ensemble_parts),
            lambda: _crossover([summaries[name] for name in ensemble_parts], out),
        )
    )
    paper_part = f"disorder-{FIGURES_ENSEMBLE}"
    friction_parts = [f"friction-{friction_name(mu)}" for mu in settings.frictions]
    parts += [
        (
            name,
            f"ensemble with friction μ = {mu:g}",
            (paper_part,),
            lambda mu=mu: run_friction_ensemble(mu, settings, parsl, out, scaling_json),
        )
        for name, mu in zip(friction_parts, settings.frictions)
    ]
    parts.append(
        (
            "friction",
            "friction and rotation study",
            (paper_part, *friction_parts),
            lambda: _friction_summary(
                settings, {mu: summaries[name] for name, mu in zip(friction_parts, settings.frictions)}, out
            ),
        )
    )
    summaries: dict = {}
    computed: set = set()
    bar = progress_bar(len(parts), "hexdem paper", unit="part")
    start = time.perf_counter()
    with silenced():
        for k, (name, label, inputs, work) in enumerate(parts, 1):
            marker = out / "parts" / f"{name}.json"
            bar.set_description(label)
            if marker.exists() and not computed.intersection(inputs):
                summaries[name] = json.loads(marker.read_text())["summary"]
                bar.write(f"hexdem paper: [{k}/{len(parts)}] {label}: done before", file=sys.stderr)
            else:
                begun = time.perf_counter()
                summary = work()
                ensure_writable_dir(marker.parent)
                write_json(marker, {"summary": summary, "wall_time_s": time.perf_counter() - begun})
                summaries[name] = json.loads(marker.read_text())["summary"]
                computed.add(name)
                bar.write(
                    f"hexdem paper: [{k}/{len(parts)}] {label}: {time.perf_counter() - begun:.1f} s", file=sys.stderr
                )
            bar.update(1)
        bar.close()
        write_report(out, settings, summaries, time.perf_counter() - start)
    return summaries, time.perf_counter() - start
