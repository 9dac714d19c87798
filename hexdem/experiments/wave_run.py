"""One run whose velocity field is recorded for linear-wave analysis: engine → samples →
:class:`~hexdem.analysis.wave_recorder.WaveRecorder` (no pulse tracking, no dump).

The linear-wave studies (:mod:`hexdem.waves`) set their excitation through the configuration's
``initial_state_file`` and read the plane-wave components and energy blocks back, on one rank
in-process or on several under MPI like every other run (:mod:`hexdem.experiments.parallel`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexdem.analysis.wave_recorder import RecordedWaves, WaveRecorder
from hexdem.experiments.parallel import run_on_ranks
from hexdem.experiments.tracked_run import make_engine, observed_run
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings


@dataclass(frozen=True)
class WaveJob:
    """What every rank of one recorded run does (picklable): ``wave_vectors_m`` (Q, 2) [1/m],
    ``block`` samples per energy block and the beads' ``weights`` (empty: all 1) as
    :class:`WaveRecorder` takes them."""

    model: GranularModel
    settings: RunSettings
    engine: str
    directory: Path
    wave_vectors_m: tuple = ()
    block: int = 0
    show_progress: bool = True
    weights: tuple = ()

    def __call__(self, comm):
        recorder = WaveRecorder(
            self.model, self.settings, np.asarray(self.wave_vectors_m, float), self.block, comm, self.weights or None
        )
        return observed_run(make_engine(self.engine), self, recorder, comm)[0]


def steps_per_sample(dt_s: float, period_s: float, samples_per_period: int) -> int:
    """The ``dump_every`` that samples about ``samples_per_period`` times per ``period_s`` with
    the time step ``dt_s``: the whole steps in period / samples, at least one."""
    return max(1, int(period_s / samples_per_period / dt_s))


def record_waves(
    config: RunConfig, workdir, wave_vectors_m=(), block: int = 0, log=None, show_progress: bool = True, weights=()
) -> RecordedWaves:
    """Run ``config`` in ``workdir`` on its engine and ranks, recording the plane-wave components
    at ``wave_vectors_m`` [1/m], each bead weighted by ``weights`` (N,) (empty: all 1), and the
    energy blocks of ``block`` samples."""
    model = build_model(config)
    settings = run_settings(config, model)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    if log is not None:
        log(
            f"running {config.engine}: {len(model.packing)} beads, {settings.n_steps} steps of "
            f"{settings.dt_s:.4g} s, {settings.n_samples} samples recorded"
        )
    job = WaveJob(
        model,
        settings,
        config.engine,
        workdir,
        tuple(map(tuple, np.asarray(wave_vectors_m, float).reshape(-1, 2))),
        block,
        show_progress,
        tuple(map(float, weights)),
    )
    return run_on_ranks(job, config.processes, workdir, config.launcher)
