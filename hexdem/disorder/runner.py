"""Running a disorder ensemble: its preparation and its impacts, every deck a task.

Three phases, compact → settle → impacts, each deck of each phase one task of the study
executor (:mod:`hexdem.experiments.executors`: ``workers`` local processes, or Parsl). A
preparation deck runs in ``lmp`` (:func:`~hexdem.engines.lammps.standalone.run_deck`); an
impact in one LAMMPS with the tracker inside (:mod:`hexdem.disorder.impacts`), publishing its
``impact.npz``. Each realization's ``result.npz`` is then assembled, and
:func:`run_ensemble` writes the statistics (:mod:`hexdem.disorder.stats`). See
:mod:`hexdem.disorder.ensemble` for resuming, determinism and the directory layout.
"""

from __future__ import annotations

import json
import shutil
import sys
import time
from pathlib import Path

from hexdem.common.io import ensure_writable_dir, locked_directory, write_json
from hexdem.disorder.ensemble import MANIFEST_NAME, PHASE_LABELS, Ensemble, EnsembleConfig
from hexdem.disorder.ensemble_figures import fitted_laws
from hexdem.disorder.impacts import impact_done, impact_task, publish_result
from hexdem.disorder.preparation import STAGES, write_stage_deck
from hexdem.disorder.sharing import adopt_ideal_impacts, adopt_preparation
from hexdem.disorder.stats import write_statistics
from hexdem.engines.lammps.standalone import is_done, run_deck
from hexdem.errors import HexdemError, one_line
from hexdem.experiments.executors import check_study_options, holding, parsl_session, run_phase, tasks_failed


def _check_manifest(out: Path, config: EnsembleConfig) -> dict:
    path = out / MANIFEST_NAME
    if not path.exists():
        manifest = {"config": config.as_dict()}
        write_json(path, manifest)
        return manifest
    try:
        manifest = json.loads(path.read_text())
        previous = EnsembleConfig.identity_of(manifest["config"])
    except (OSError, ValueError, KeyError, AttributeError, TypeError):
        raise HexdemError(
            f"{path} is unreadable: {out} does not hold a hexdem ensemble; choose another --out"
        ) from None
    if previous != config.identity():
        changed = sorted(
            key for key in set(previous) | set(config.identity()) if previous.get(key) != config.identity().get(key)
        )
        raise HexdemError(
            f"{out} holds an ensemble with other parameters ({', '.join(changed)}); "
            "rerun with the same parameters to resume it, or choose another --out"
        )
    return manifest


def _pending_impacts(ensemble: Ensemble, groups) -> list[tuple[int | None, float]]:
    """(realization or None, striker speed) of every impact of ``groups`` without its result."""
    return [(k, v) for k in groups for v in ensemble.config.velocities_m_s if not impact_done(ensemble, k, v)]


def _run_phase(name: str, tasks: dict, workers: int, parsl, on_done=None) -> None:
    """Run the phase ``name``'s ``tasks`` {what: (fn, *args)}, one task of the study executor
    each (:func:`~hexdem.experiments.executors.run_phase`), calling ``on_done()`` as each
    finishes; the tasks that failed are named at the end."""
    failed, errors = [], []
    for what, error in run_phase(tasks, workers, parsl, PHASE_LABELS[name], "deck"):
        if error is not None:
            failed.append(f"{what}: {one_line(error)}")
            errors.append(error)
        if on_done is not None:
            on_done()
    if failed:
        raise tasks_failed(
            f"{len(failed)} of {len(tasks)} {name} decks failed (rerun to run them again); {'; '.join(failed)}", errors
        )


def run_ensemble(
    config: EnsembleConfig,
    out,
    workers: int = 1,
    launcher: str | None = None,
    parsl=None,
    keep_dumps: bool = False,
    scaling_json=None,
    log=None,
    share_from=(),
) -> dict:
    """Run (or resume) the ensemble in ``out`` and write its statistics; returns the summary.

    ``workers`` decks run at once in local processes, or on Parsl with the configuration file
    ``parsl`` (or its :class:`~hexdem.experiments.executors.ParslSession`), one Parsl for all the
    phases, each deck on one rank (started by the MPI launcher ``launcher`` when given);
    ``scaling_json`` adds the fitted laws to Fig. 9;
    ``share_from`` other :class:`Ensemble` s whose identical finished runs are copied rather
    than run again (:mod:`hexdem.disorder.sharing`).
    """
    log = log or (lambda message: print(f"hexdem ensemble: {message}", file=sys.stderr, flush=True))
    check_study_options(workers, launcher)
    parsl = parsl_session(parsl, out)
    laws = fitted_laws(scaling_json, config.disorder.diameter_m) if scaling_json else {}
    out = ensure_writable_dir(out)
    ensemble = Ensemble(config, out)
    with (
        locked_directory(out, "another hexdem ensemble (or its LAMMPS is still shutting down)"),
        holding(parsl, workers),
    ):
        manifest = _check_manifest(out, config)
        for leftover in list(out.rglob(".*.part")):  # atomic writes and copies cut short by a killed run
            if leftover.is_dir():
                shutil.rmtree(leftover, ignore_errors=True)
            else:
                leftover.unlink(missing_ok=True)
        for source in share_from:
            adopt_ideal_impacts(ensemble, source)
            adopt_preparation(ensemble, source)
        todo = [k for k in range(config.realizations) if not ensemble.result_path(k).exists()]
        ideal_todo = not ensemble.result_path(None).exists()
        log(
            f"{config.realizations} realizations x {len(config.velocities_m_s)} striker velocities, "
            f"{ensemble.ideal.shape}, seed {config.seed}: {len(todo)} to run, {workers} workers"
        )
        wall: dict[str, float] = {}

        for stage in STAGES:
            pending = [k for k in todo if not is_done(ensemble.stage_dir(k, stage))]
            for k in pending:
                shutil.rmtree(ensemble.stage_dir(k, stage), ignore_errors=True)
                write_stage_deck(
                    ensemble.stage_model(k, stage), stage, config.preparation, ensemble.stage_dir(k, stage)
                )
            log(f"{stage}: {len(pending)} decks")
            start = time.perf_counter()
            _run_phase(
                stage,
                {f"realization {k}": (run_deck, ensemble.stage_dir(k, stage), launcher) for k in pending},
                workers,
                parsl,
            )
            wall[stage] = time.perf_counter() - start

        groups = [*todo, *([None] if ideal_todo else [])]
        tasks = _pending_impacts(ensemble, groups)
        log(f"impacts: {len(tasks)} runs, analysed as they run")
        start = time.perf_counter()
        published: set = set()

        def publish_finished() -> None:
            """Publish every realization whose impacts are all done."""
            for k in groups:
                if k not in published and all(impact_done(ensemble, k, v) for v in config.velocities_m_s):
                    publish_result(ensemble, k)
                    published.add(k)

        publish_finished()
        _run_phase(
            "impacts",
            {
                f"{'ideal' if k is None else f'realization {k}'} at {v:g} m/s": (
                    impact_task,
                    config,
                    out,
                    k,
                    v,
                    keep_dumps,
                    launcher,
                )
                for k, v in tasks
            },
            workers,
            parsl,
            publish_finished,
        )
        wall["impacts"] = time.perf_counter() - start
        summary = write_statistics(ensemble, laws)
        summary["this_run"] = {
            "realizations_run": len(todo),
            "workers": workers,
            "wall_time_s": {name: round(t, 3) for name, t in wall.items()},
        }
        write_json(out / MANIFEST_NAME, {**manifest, "config": config.as_dict(), **summary})
        log(f"done ({', '.join(f'{name} {t:.1f} s' for name, t in wall.items())}); results in {out}")
        for v, warnings in zip(config.velocities_m_s, summary["impact_warnings"]):
            if warnings:
                log(f"impacts at {v:g} m/s warned (the warnings column of peaks_stats.csv): {warnings}")
        return summary
