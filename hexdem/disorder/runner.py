"""Running a disorder ensemble: phases on LAMMPS partitions, per-realization analysis, resuming.

Three phases, compact → settle → impacts, each run all pending decks of
:class:`~hexdem.disorder.ensemble.Ensemble` on LAMMPS partitions
(:mod:`hexdem.engines.lammps.partitions`). A realization's impacts are analysed (in
``workers`` spawned processes) as soon as its last deck finishes, and its ``result.npz``
published atomically; :func:`run_ensemble` then writes the statistics
(:mod:`hexdem.disorder.stats`). See :mod:`hexdem.disorder.ensemble` for resuming,
determinism and the directory layout.
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.common.checks import positive_int
from hexdem.common.io import atomic_path, ensure_writable_dir, write_json
from hexdem.common.progress import progress_bar
from hexdem.disorder.ensemble import MANIFEST_NAME, PHASE_LABELS, Ensemble, EnsembleConfig
from hexdem.disorder.figures import fitted_laws
from hexdem.disorder.preparation import STAGES, TiltedTrajectory, contact_overlaps_m, read_stage, write_stage_deck
from hexdem.disorder.stats import write_statistics
from hexdem.engines.lammps.deck import DUMP_NAME, Deck, write_deck
from hexdem.engines.lammps.engine import read_trajectory
from hexdem.engines.lammps.partitions import die_with_parent, is_done, lammps_version, run_info, run_partitioned
from hexdem.errors import HexdemError
from hexdem.experiments.run import MAX_ENERGY_DRIFT

# --------------------------------------------------------------------------- analysis


def _analyse(ensemble: Ensemble, k: int | None, v: float, version: str) -> ImpactAnalysis:
    directory = ensemble.ideal_dir(v) if k is None else ensemble.impact_dir(k, v)
    model, settings = ensemble.impact_model(k, v), ensemble.settings(v)
    trajectory = read_trajectory(Deck(directory, settings, model.n_bodies), run_info(directory, version))
    if k is not None:
        trajectory = TiltedTrajectory.tilt(trajectory, ensemble.gravity_m_s2)
    return ImpactAnalysis(model, settings, trajectory).run()


def _impact_arrays(analyses: list[ImpactAnalysis]) -> dict:
    return {
        "velocities_m_s": np.array([a.model.impact.speed_m_s for a in analyses]),
        "peak_speed": np.array([a.results.peak_speed for a in analyses]),
        "t_peak": np.array([a.results.t_peak for a in analyses]),
        "arrival_time": np.array([a.results.arrival_time for a in analyses]),
        "energy_drift": np.array([a.results.energy_drift for a in analyses]),
        "far_wall_reached": np.array([a.results.far_wall_reached for a in analyses]),
        "impact_lammps_s": np.array([a.trajectory.engine["wall_time_s"] for a in analyses]),
    }


def analyse(ensemble: Ensemble, k: int | None, version: str, keep_dumps: bool = False) -> float:
    """Analyse every impact of realization k (None: the ideal lattice), publish its
    ``result.npz`` and drop its dumps unless ``keep_dumps``; returns the time taken [s]."""
    start = time.perf_counter()
    analyses = [_analyse(ensemble, k, v, version) for v in ensemble.config.velocities_m_s]
    for analysis in analyses:
        if not analysis.results.energy_drift <= MAX_ENERGY_DRIFT:
            raise HexdemError(f"energy drift {analysis.results.energy_drift:.1e} exceeds {MAX_ENERGY_DRIFT:g} in "
                              f"{analysis.trajectory.engine['deck']}: the run is not trustworthy")
    arrays = _impact_arrays(analyses)
    if k is not None:
        lattice = analyses[0].model.lattice
        arrays.update(diameters_m=lattice.diameters_m, positions_m=lattice.positions_m,
                      wall_offsets_m=np.array([w.offset_m for w in lattice.walls]),
                      max_overlap_m=float(np.max(contact_overlaps_m(lattice.positions_m, lattice.diameters_m),
                                                 initial=0.0)))
        for stage in STAGES:
            result = read_stage(ensemble.stage_dir(k, stage))
            arrays[f"{stage}_steps"] = result.steps
            arrays[f"{stage}_time_s"] = result.time_s
            arrays[f"{stage}_kinetic_energy_j"] = result.kinetic_energy_j
            arrays[f"{stage}_max_force_n"] = result.max_force_n
            arrays[f"{stage}_lammps_s"] = run_info(ensemble.stage_dir(k, stage), version).wall_time_s
    with atomic_path(ensemble.result_path(k)) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **arrays)
    if not keep_dumps:
        for directory in ensemble.impact_dirs(k):
            (directory / DUMP_NAME).unlink(missing_ok=True)
    return time.perf_counter() - start


# --------------------------------------------------------------------------- running


def _analysis_worker(parent_pid: int) -> None:
    """Set-up of an analysis process: it dies with hexdem, and shows no per-dump progress
    bars (errors reach hexdem through the futures; hexdem shows one bar for all)."""
    die_with_parent(parent_pid)
    sys.stderr = open(os.devnull, "w")


@contextmanager
def _locked(out: Path):
    """Hold ``OUT/.lock`` (also inherited by the MPI launcher) so two runs never share OUT."""
    fd = os.open(out / ".lock", os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise HexdemError(f"{out} is in use by another hexdem ensemble (or its LAMMPS is still "
                              "shutting down); wait for it or choose another --out") from None
        yield fd
    finally:
        os.close(fd)


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
        raise HexdemError(f"{path} is unreadable: {out} does not hold a hexdem ensemble; "
                          "choose another --out") from None
    if previous != config.identity():
        changed = sorted(key for key in set(previous) | set(config.identity())
                         if previous.get(key) != config.identity().get(key))
        raise HexdemError(f"{out} holds an ensemble with other parameters ({', '.join(changed)}); "
                          "rerun with the same parameters to resume it, or choose another --out")
    return manifest


def _pending_impacts(ensemble: Ensemble, todo: list[int], ideal_todo: bool) -> dict[Path, int | None]:
    """Render every impact deck not yet done: {deck directory: realization (None: ideal)}."""
    pending = {}
    for k in [*todo, *([None] if ideal_todo else [])]:
        for v, directory in zip(ensemble.config.velocities_m_s, ensemble.impact_dirs(k)):
            if not is_done(directory):
                write_deck(ensemble.impact_model(k, v), ensemble.settings(v), directory,
                           gravity_m_s2=None if k is None else ensemble.gravity_m_s2)
                pending[directory] = k
    return pending


def run_ensemble(config: EnsembleConfig, out, workers: int = 1, launcher: str | None = None,
                 keep_dumps: bool = False, scaling_json=None, log=None) -> dict:
    """Run (or resume) the ensemble in ``out`` and write its statistics; returns the summary.

    ``workers`` LAMMPS partitions run at once, started by ``launcher`` (default: this
    environment's ``mpiexec``); ``scaling_json`` adds the fitted laws to Fig. 9.
    """
    log = log or (lambda message: print(f"hexdem ensemble: {message}", file=sys.stderr, flush=True))
    positive_int("--workers", workers)
    laws = fitted_laws(scaling_json, config.disorder.diameter_m) if scaling_json else {}
    out = ensure_writable_dir(out)
    ensemble = Ensemble(config, out)
    with _locked(out) as lock:
        manifest = _check_manifest(out, config)
        for leftover in out.rglob(".*.part"):  # atomic writes cut short by a killed run
            leftover.unlink()
        todo = [k for k in range(config.realizations) if not ensemble.result_path(k).exists()]
        ideal_todo = not ensemble.result_path(None).exists()
        log(f"{config.realizations} realizations x {len(config.velocities_m_s)} striker velocities, "
            f"{ensemble.ideal.shape}, seed {config.seed}: {len(todo)} to run, {workers} workers")
        wall: dict[str, float] = {"analysis": 0.0}  # analysis: summed over its worker processes

        def run_phase(name: str, directories, on_done=None) -> None:
            start = time.perf_counter()
            run_partitioned(directories, workers, out / "lammps" / name, PHASE_LABELS[name], launcher,
                            on_done=on_done, pass_fds=(lock,))
            wall[name] = time.perf_counter() - start

        for stage in STAGES:
            pending = [k for k in todo if not is_done(ensemble.stage_dir(k, stage))]
            for k in pending:
                shutil.rmtree(ensemble.stage_dir(k, stage), ignore_errors=True)
                write_stage_deck(ensemble.stage_model(k, stage), stage, config.preparation,
                                 ensemble.stage_dir(k, stage))
            log(f"{stage}: {len(pending)} decks")
            run_phase(stage, [ensemble.stage_dir(k, stage) for k in pending])

        impacts = _pending_impacts(ensemble, todo, ideal_todo)
        groups = [*todo, *([None] if ideal_todo else [])]
        log(f"impacts: {len(impacts)} decks")
        with ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"),
                                 initializer=_analysis_worker, initargs=(os.getpid(),)) as pool:
            analyses = {}

            def analyse_if_complete(k: int | None) -> None:
                if k not in analyses and not ensemble.result_path(k).exists() and all(
                        is_done(d) for d in ensemble.impact_dirs(k)):
                    version = lammps_version(out / "lammps" / "impacts")
                    analyses[k] = pool.submit(analyse, ensemble, k, version, keep_dumps)

            run_phase("impacts", list(impacts), on_done=lambda directory: analyse_if_complete(impacts[directory]))
            for k in groups:
                analyse_if_complete(k)
            start, bar = time.perf_counter(), progress_bar(len(analyses), "analysing", unit="realization")
            for future in as_completed(analyses.values()):
                wall["analysis"] += future.result()
                bar.update(1)
            bar.close()
            wall["waiting for analysis"] = time.perf_counter() - start
        summary = write_statistics(ensemble, laws)
        summary["this_run"] = {"realizations_run": len(todo), "workers": workers,
                               "wall_time_s": {name: round(t, 3) for name, t in wall.items()}}
        write_json(out / MANIFEST_NAME, {**manifest, "config": config.as_dict(), **summary})
        log(f"done ({', '.join(f'{name} {t:.1f} s' for name, t in wall.items())}); results in {out}")
        return summary
