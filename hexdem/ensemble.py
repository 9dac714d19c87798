"""Ensembles of weakly disordered packings struck by a striker sphere (Sec. VI; Figs. 8, 9).

Every realization k is prepared as in Sec. VI-A (:mod:`hexdem.disorder`: diameters from
(seed, k), compaction by 5 N edge forces, walls, gravity settle) once, and its settled
packing is struck at every velocity of the ensemble. The ideal lattice (equal diameters,
no gravity, as in the paper's ideal simulations) is struck by the same striker for
reference. Striker: steel, nominal diameter, touching the edge-centre bead at t = 0 and
entering through the hole in the wall.

**Running.** Three phases, compact → settle → impacts, each running all its pending decks
on LAMMPS partitions (:mod:`hexdem.lammps.partitions`): ``workers`` one-rank LAMMPS
instances here, or as many as an MPI launcher reaches across machines. A realization's
impacts are analysed (in ``workers`` spawned processes) as soon as its last deck finishes.

**Resuming.** A deck is finished when it has its done marker; a realization when its
``result.npz`` exists (written atomically once all its impacts are analysed; the dumps are
then deleted unless ``keep_dumps``). A rerun with the same parameters skips both and redoes
only what is missing; nothing half-written is ever read. More realizations can be added
later: realization k does not depend on how many there are.

**Determinism.** The same seed gives the same diameters and, LAMMPS being deterministic
on one rank, bit-identical results, however many workers share the work.

**Layout of OUT**: ``ensemble.json`` (parameters, timings, disorder effect),
``realizations/r0007/{compact,settle,v0.400,...}/`` decks and ``result.npz``,
``ideal/v0.400/`` decks and ``ideal/result.npz``, ``lammps/<phase>/`` partition drivers,
and the tables and figures of :func:`hexdem.ensemble_stats.write_statistics`.
"""

from __future__ import annotations

import dataclasses
import fcntl
import json
import os
import shutil
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from hexdem.config import RunConfig
from hexdem.disorder import (SETTLED_NAME, STAGES, Disorder, Preparation, TiltedTrajectory, contact_overlaps_m,
                             read_data_file, read_stage, spaced_lattice, write_stage_deck)
from hexdem.checks import is_number, positive_int
from hexdem.errors import HexdemError
from hexdem.experiment import MAX_ENERGY_DRIFT
from hexdem.impact import ImpactAnalysis
from hexdem.io import atomic_path, ensure_writable_dir, write_json
from hexdem.lammps.deck import DUMP_NAME, Deck, write_deck
from hexdem.lammps.engine import read_trajectory
from hexdem.lammps.partitions import die_with_parent, is_done, lammps_version, run_info, run_partitioned
from hexdem.lattice import Lattice
from hexdem.model import GranularModel, RunSettings
from hexdem.progress import progress_bar

RESULT_NAME = "result.npz"
MANIFEST_NAME = "ensemble.json"
#: Progress-bar labels of the phases.
PHASE_LABELS = {"compact": "compacting", "settle": "settling", "impacts": "impacts"}


@dataclass(frozen=True)
class EnsembleConfig:
    """An ensemble: ``realizations`` packings of a hexagon with ``edge_beads`` per edge,
    each struck at every striker speed of ``velocities_m_s`` [m/s].

    ``seed`` seeds every realization's diameters; ``disorder`` and ``preparation`` are Sec.
    VI-A; ``dump_every`` steps between samples (50 steps of 0.1 µs: peaks within 1e-4 and
    arrival times within 3 ns of every-other-step sampling); ``duration_s`` run length [s]
    (None: the ideal crossing estimate of :class:`~hexdem.config.RunConfig` times
    ``duration_factor``: 1.5 lets the slower disordered wave reach the lines' far beads,
    while the far wall's reflection has not yet changed the ideal lattice's peaks, which it
    does at 1.75); ``reference_bead`` {m, n} the bead whose arrival is t = 0 in the maps
    (Fig. 8's white x; default: bead 1 of the 0° line, the sensor nearest the impact).
    """

    realizations: int = 20
    velocities_m_s: tuple[float, ...] = (0.25, 0.40, 0.70)
    seed: int = 0
    edge_beads: int = 11
    disorder: Disorder = field(default_factory=lambda: Disorder(RunConfig().diameter_m))
    preparation: Preparation = field(default_factory=Preparation)
    dump_every: int = 50
    duration_s: float | None = None
    duration_factor: float = 1.5
    reference_bead: tuple[int, int] = (0, 2)

    def __post_init__(self):
        positive_int("the number of realizations", self.realizations)
        positive_int("dump_every", self.dump_every)
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise HexdemError(f"the seed must be a non-negative integer, got {self.seed!r}")
        speeds = tuple(self.velocities_m_s)
        if not speeds or len(set(speeds)) != len(speeds) or not all(
                is_number(v) and v > 0 for v in speeds):
            raise HexdemError(f"striker velocities must be distinct positive speeds in m/s, got {speeds!r}")
        object.__setattr__(self, "velocities_m_s", tuple(float(v) for v in speeds))
        if self.duration_s is not None and not (is_number(self.duration_s) and self.duration_s > 0):
            raise HexdemError(f"duration must be a positive time in s, got {self.duration_s!r}")
        if not (is_number(self.duration_factor) and self.duration_factor >= 1):
            raise HexdemError(f"duration_factor must be >= 1, got {self.duration_factor!r}")
        ideal = self.ideal_lattice()
        if ideal.index_of(*self.reference_bead) is None:
            raise HexdemError(f"reference bead {{{self.reference_bead[0]}, {self.reference_bead[1]}}} "
                              f"is not in the {ideal.shape}")

    def run_config(self, v_striker: float) -> RunConfig:
        """The ideal-lattice striker run at ``v_striker`` (also sets every run's dt and length)."""
        base = RunConfig(shape="hexagon", edge_beads=self.edge_beads, diameter_m=self.disorder.diameter_m,
                         impact="striker", v0=float(v_striker), dump_every=self.dump_every)
        if self.duration_s is not None:
            return base.replace(duration=self.duration_s)
        return base.replace(duration=self.duration_factor * base.settings().duration_s)

    def ideal_lattice(self) -> Lattice:
        return self.run_config(self.velocities_m_s[0]).lattice()

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)

    def identity(self) -> dict:
        """Everything that determines a realization's results: all but the number of
        realizations and the preparation's step limit (which only decides whether a stage
        that has not settled yet goes on)."""
        return self.identity_of(self.as_dict())

    @staticmethod
    def identity_of(config: dict) -> dict:
        identity = json.loads(json.dumps(config))
        del identity["realizations"], identity["preparation"]["max_steps"]
        return identity


def velocity_name(v: float) -> str:
    """Directory and figure suffix of striker speed ``v`` [m/s], e.g. ``v0.400``."""
    return f"v{v:.3f}"


class Ensemble:
    """An ensemble directory: where each deck and result lives, and the models behind them."""

    def __init__(self, config: EnsembleConfig, out):
        self.config, self.out = config, Path(out)
        self.ideal = config.ideal_lattice()
        self._base_model = config.run_config(config.velocities_m_s[0]).model()

    # ---- layout
    def realization_dir(self, k: int) -> Path:
        return self.out / "realizations" / f"r{k:04d}"

    def stage_dir(self, k: int, stage: str) -> Path:
        return self.realization_dir(k) / stage

    def impact_dir(self, k: int, v: float) -> Path:
        return self.realization_dir(k) / velocity_name(v)

    def ideal_dir(self, v: float) -> Path:
        return self.out / "ideal" / velocity_name(v)

    def result_path(self, k: int | None) -> Path:
        """``result.npz`` of realization k (None: the ideal lattice)."""
        return self.out / "ideal" / RESULT_NAME if k is None else self.realization_dir(k) / RESULT_NAME

    def impact_dirs(self, k: int | None) -> list[Path]:
        """The impact decks of realization k (None: the ideal lattice), one per velocity."""
        return [self.ideal_dir(v) if k is None else self.impact_dir(k, v) for v in self.config.velocities_m_s]

    # ---- models
    def settings(self, v: float) -> RunSettings:
        return self.config.run_config(v).settings()

    def diameters_m(self, k: int) -> np.ndarray:
        return self.config.disorder.diameters_m(len(self.ideal), self.config.seed, k)

    def stage_model(self, k: int, stage: str) -> GranularModel:
        """The packing a preparation stage starts from: spaced (compact) or compacted with walls (settle)."""
        if stage == "compact":
            spaced = spaced_lattice(self.ideal, self.diameters_m(k), self.config.disorder)
            return replace(self._base_model, lattice=spaced)
        compacted = self._stage_state(k, "compact")
        return replace(self._base_model, lattice=self.ideal.with_geometry(compacted.positions_m, compacted.diameters_m))

    def _stage_state(self, k: int, stage: str):
        directory = self.stage_dir(k, stage)
        result = read_stage(directory)
        if not result.settled:
            raise HexdemError(f"realization {k}: stage {stage!r} did not settle in {result.steps} steps "
                              f"(kinetic energy {result.kinetic_energy_j:.3g} J, tolerance {result.tolerance_j:.3g} J; "
                              f"largest force {result.max_force_n:.3g} N, tolerance {result.force_tolerance_n:.3g} N); "
                              "rerun with a larger --max-settle-steps")
        return read_data_file(directory / SETTLED_NAME)

    def settled_lattice(self, k: int) -> Lattice:
        """The settled packing of realization k, with the walls placed after compaction."""
        walled = self.stage_model(k, "settle").lattice
        settled = self._stage_state(k, "settle")
        return replace(walled, positions_m=settled.positions_m, diameters_m=settled.diameters_m)

    def impact_model(self, k: int | None, v: float) -> GranularModel:
        """Realization k (None: the ideal lattice) struck at ``v``."""
        model = self.config.run_config(v).model()
        return model if k is None else replace(model, lattice=self.settled_lattice(k))

    @property
    def gravity_m_s2(self) -> np.ndarray:
        return self.config.preparation.gravity_vector_m_s2(self._base_model.impact.direction)


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
    from hexdem.ensemble_plots import fitted_laws
    from hexdem.ensemble_stats import write_statistics

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
