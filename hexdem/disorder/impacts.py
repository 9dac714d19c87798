"""The impacts of a disorder ensemble, analysed while they run, spread over MPI ranks.

Every impact (realization k, or the ideal lattice, at one striker speed) is one tracked run
(:mod:`hexdem.experiments.tracked_run`) whose results go atomically into ``impact.npz`` in
its deck directory: that file is the impact's done marker, so an interrupted ensemble
resumes with the impacts that lack it. :class:`ImpactTasks` is an MPI job
(:mod:`hexdem.experiments.parallel`): the world communicator is split into one-rank
communicators, one LAMMPS each, and rank r takes tasks r, r + P, r + 2P, … of the list
(all impacts cost about the same). A realization's ``result.npz`` is assembled from its
impacts and its preparation once all of them exist (:func:`publish_result`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.analysis.leading_pulse import leading_pulse_amplitude
from hexdem.common.io import atomic_path
from hexdem.disorder.ensemble import Ensemble, EnsembleConfig
from hexdem.disorder.preparation import STAGES
from hexdem.disorder.prestress import prestress
from hexdem.engines.lammps.partitions import loop_time_s
from hexdem.engines.lammps.settling import read_stage
from hexdem.experiments.parallel import spread_tasks
from hexdem.experiments.run import check_energy
from hexdem.experiments.tracked_run import ImpactJob, track_impact

IMPACT_NAME = "impact.npz"
#: Arrays of ``impact.npz``, stacked over the striker speeds in ``result.npz``.
IMPACT_ARRAYS = ("peak_speed", "lead_speed", "t_peak", "arrival_time", "energy_drift", "far_wall_reached", "impact_lammps_s")


def _save(path: Path, arrays: dict) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **arrays)


def _load(path: Path) -> dict:
    with np.load(path) as data:
        return {name: data[name] for name in data.files}


def run_impact(ensemble: Ensemble, k: int | None, v: float, dump: bool, comm=None) -> str:
    """Run and analyse one impact of realization k (None: ideal) at striker speed ``v`` [m/s]
    on the ranks of ``comm`` (None: this process); write its ``impact.npz``. Returns the
    LAMMPS version."""
    directory = ensemble.impact_dir(k, v)
    gravity = None if k is None else tuple(float(g) for g in ensemble.gravity_m_s2)
    line_beads = tuple(sorted({int(b) for beads in ensemble.ideal.lines().values() for b in beads}))
    job = ImpactJob(ensemble.impact_model(k, v), ensemble.settings(v), "lammps", directory, dump=dump,
                    gravity_m_s2=gravity, trace_beads=line_beads, show_progress=False)
    analysis: ImpactAnalysis = track_impact(job, comm=comm)
    check_energy(analysis, analysis.engine["deck"])
    r = analysis.results
    lead = np.full(len(r.peak_speed), np.nan)
    lead[list(line_beads)] = leading_pulse_amplitude(analysis.tracked.trace_speeds)
    _save(directory / IMPACT_NAME, {"peak_speed": r.peak_speed, "lead_speed": lead, "t_peak": r.t_peak,
                                    "arrival_time": r.arrival_time, "energy_drift": r.energy_drift,
                                    "far_wall_reached": r.far_wall_reached,
                                    "impact_lammps_s": analysis.engine["wall_time_s"]})
    return analysis.engine["version"]


@dataclass(frozen=True)
class ImpactTasks:
    """An MPI job: the impacts ``tasks`` [(realization or None, striker speed)] of the ensemble
    ``config`` in ``out``, spread over the ranks. Returns the LAMMPS version (rank 0)."""

    config: EnsembleConfig
    out: Path
    tasks: tuple[tuple[int | None, float], ...]
    dump: bool = False

    def __call__(self, comm):
        ensemble = Ensemble(self.config, self.out)
        versions = spread_tasks(comm, self.tasks, lambda task, alone: run_impact(ensemble, *task, self.dump, alone))
        return None if versions is None else next(iter(versions), "unknown")


def impact_done(ensemble: Ensemble, k: int | None, v: float) -> bool:
    return (ensemble.impact_dir(k, v) / IMPACT_NAME).exists()


def publish_result(ensemble: Ensemble, k: int | None) -> None:
    """Assemble realization k's (None: the ideal lattice's) ``result.npz`` from its impacts
    (stacked over the striker speeds) and, for a realization, its packing, the prestress it
    keeps and its preparation."""
    impacts = [_load(directory / IMPACT_NAME) for directory in ensemble.impact_dirs(k)]
    arrays = {"velocities_m_s": np.array(ensemble.config.velocities_m_s)}
    arrays.update({name: np.array([impact[name] for impact in impacts]) for name in IMPACT_ARRAYS})
    if k is not None:
        model = ensemble.impact_model(k, ensemble.config.velocities_m_s[0])
        lattice, load = model.lattice, prestress(model)
        arrays.update(diameters_m=lattice.diameters_m, positions_m=lattice.positions_m,
                      wall_offsets_m=np.array([w.offset_m for w in lattice.walls]),
                      max_overlap_m=load.max_overlap_m, **load.as_arrays())
        for stage in STAGES:
            result = read_stage(ensemble.stage_dir(k, stage))
            arrays[f"{stage}_steps"] = result.steps
            arrays[f"{stage}_time_s"] = result.time_s
            arrays[f"{stage}_kinetic_energy_j"] = result.kinetic_energy_j
            arrays[f"{stage}_max_force_n"] = result.max_force_n
            arrays[f"{stage}_lammps_s"] = loop_time_s(ensemble.stage_dir(k, stage) / "log.lammps")
    _save(ensemble.result_path(k), arrays)
