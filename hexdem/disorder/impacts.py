"""The impacts of a disorder ensemble, analysed while they run, one task each.

Every impact (realization k, or the ideal lattice, at one striker speed) is one tracked run
(:mod:`hexdem.experiments.tracked_run`) whose results go atomically into ``impact.npz`` in
its deck directory: that file is the impact's done marker, so an interrupted ensemble
resumes with the impacts that lack it. :func:`impact_task` is one task of the study
executor (:mod:`hexdem.experiments.executors`): one LAMMPS rank, in the worker's process or
started by the MPI launcher. A realization's ``result.npz`` is assembled from its impacts
and its preparation once all of them exist (:func:`publish_result`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.analysis.leading_pulse import leading_pulse_amplitude
from hexdem.common.io import atomic_path
from hexdem.disorder.ensemble import Ensemble, EnsembleConfig
from hexdem.disorder.preparation import STAGES
from hexdem.disorder.prestress import prestress
from hexdem.engines.lammps.settling import read_stage
from hexdem.engines.lammps.standalone import loop_time_s
from hexdem.experiments.run import check_energy
from hexdem.experiments.tracked_run import ImpactJob, track_impact

IMPACT_NAME = "impact.npz"
#: Arrays of ``impact.npz``, stacked over the striker speeds in ``result.npz``.
IMPACT_ARRAYS = (
    "peak_speed",
    "lead_speed",
    "t_peak",
    "arrival_time",
    "energy_drift",
    "far_wall_reached",
    "impact_lammps_s",
)


def _save(path: Path, arrays: dict) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **arrays)


def _load(path: Path) -> dict:
    with np.load(path) as data:
        return {name: data[name] for name in data.files}


def run_impact(ensemble: Ensemble, k: int | None, v: float, dump: bool, launcher: str | None = None) -> None:
    """Run and analyse one impact of realization k (None: ideal) at striker speed ``v`` [m/s]
    on one rank (in this process, or started by ``launcher``); write its ``impact.npz``."""
    directory = ensemble.impact_dir(k, v)
    gravity = None if k is None else tuple(float(g) for g in ensemble.gravity_m_s2)
    line_beads = tuple(sorted({int(b) for beads in ensemble.ideal.lines().values() for b in beads}))
    job = ImpactJob(
        *ensemble.impact(k, v),
        "lammps",
        directory,
        dump=dump,
        gravity_m_s2=gravity,
        trace_beads=line_beads,
        show_progress=False,
    )
    analysis: ImpactAnalysis = track_impact(job, launcher=launcher)
    check_energy(analysis, analysis.engine["deck"])
    r = analysis.results
    lead = np.full(len(r.peak_speed), np.nan)
    lead[list(line_beads)] = leading_pulse_amplitude(analysis.tracked.trace_speeds)
    _save(
        directory / IMPACT_NAME,
        {
            "peak_speed": r.peak_speed,
            "lead_speed": lead,
            "t_peak": r.t_peak,
            "arrival_time": r.arrival_time,
            "energy_drift": r.energy_drift,
            "far_wall_reached": r.far_wall_reached,
            "impact_lammps_s": analysis.engine["wall_time_s"],
        },
    )


def impact_task(
    config: EnsembleConfig, out: Path, k: int | None, v: float, dump: bool, launcher: str | None = None
) -> None:
    """One impact of the ensemble ``config`` in ``out`` (see :func:`run_impact`): a task."""
    run_impact(Ensemble(config, out), k, v, dump, launcher)


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
        lattice, load = model.packing, prestress(model)
        arrays.update(
            diameters_m=lattice.diameters_m,
            positions_m=lattice.positions_m,
            wall_offsets_m=np.array([w.offset_m for w in lattice.walls]),
            max_overlap_m=load.max_overlap_m,
            **load.as_arrays(),
        )
        for stage in STAGES:
            result = read_stage(ensemble.stage_dir(k, stage))
            arrays[f"{stage}_steps"] = result.steps
            arrays[f"{stage}_time_s"] = result.time_s
            arrays[f"{stage}_kinetic_energy_j"] = result.kinetic_energy_j
            arrays[f"{stage}_max_force_n"] = result.max_force_n
            arrays[f"{stage}_lammps_s"] = loop_time_s(ensemble.stage_dir(k, stage) / "log.lammps")
    _save(ensemble.result_path(k), arrays)
