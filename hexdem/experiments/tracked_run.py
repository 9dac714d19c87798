"""One impact run with its analysis inside: engine → samples → tracker → :class:`ImpactAnalysis`.

Every study that simulates (``hexdem run``, ``compare``, ``snapshots``, the V0 sweep, the
disorder ensembles) runs its impacts through :func:`track_impact`, on one rank in-process or
on several under MPI (:mod:`hexdem.experiments.parallel`), with the same tracker.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.analysis.tracker import PulseTracker
from hexdem.engines.lammps.deck import Deck
from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.lammps.runner import logged_step
from hexdem.engines.sampling import InRunAnalysis, Results
from hexdem.experiments.parallel import run_on_ranks
from hexdem.model.granular import GranularModel, RunSettings


@dataclass(frozen=True)
class ImpactJob:
    """What every rank of one impact run does (picklable, see :mod:`hexdem.experiments.parallel`).

    ``engine``: "lammps" or "reference"; ``dump``: LAMMPS also writes its full dump;
    ``gravity_m_s2``: uniform in-plane gravity (gx, gy) [m/s²] or None; ``trace_beads`` and
    ``field_samples``: what the tracker keeps besides the pulses; ``threshold_speed`` (run units):
    a speed whose first crossing by each bead it records; ``show_progress``: a bar on a terminal.
    """

    model: GranularModel
    settings: RunSettings
    engine: str
    directory: Path
    dump: bool = False
    gravity_m_s2: tuple[float, float] | None = None
    trace_beads: tuple[int, ...] = ()
    field_samples: tuple[int, ...] = ()
    show_progress: bool = True
    threshold_speed: float | None = None

    def __call__(self, comm):
        tracker = PulseTracker(
            self.model,
            self.settings,
            comm,
            self.trace_beads,
            self.field_samples,
            self.gravity_m_s2,
            self.threshold_speed,
        )
        tracked, description = observed_run(make_engine(self.engine, self.dump, self.gravity_m_s2), self, tracker, comm)
        return None if tracked is None else (tracked, description)


def observed_run(engine, job, analysis: InRunAnalysis[Results], comm) -> tuple[Results | None, dict]:
    """Run ``job``'s model and settings on ``engine`` in its directory, ``analysis`` observing:
    (its results, None on the ranks other than 0; the engine's description of the run)."""
    description = engine.run(job.model, job.settings, job.directory, analysis, comm, job.show_progress)
    return analysis.finish(), description


def make_engine(name: str, dump: bool = False, gravity_m_s2=None):
    """The engine called ``name`` ("lammps" or "reference"); ``dump`` and ``gravity_m_s2`` are LAMMPS's."""
    if name == "reference":  # numba and its compiled kernels: only for the runs that use them
        from hexdem.engines.reference.engine import ReferenceEngine

        return ReferenceEngine()
    return LammpsEngine(dump=dump, gravity_m_s2=gravity_m_s2)


def track_impact(job: ImpactJob, ranks: int = 1, launcher: str | None = None) -> ImpactAnalysis:
    """Run ``job`` on ``ranks`` MPI ranks (LAMMPS only; 1 without ``launcher``: in this
    process) started by ``launcher`` (see :func:`~hexdem.experiments.parallel.run_on_ranks`)
    and analyse it; launched ranks show their progress through LAMMPS's log (the steps it has
    logged, every twentieth of the run), as one rank in-process does through its callback."""
    ranks = ranks if job.engine == "lammps" else 1
    launched = ranks > 1 or launcher is not None
    log = Deck(job.directory, job.settings, job.model.n_bodies).log_path
    progress = (
        (job.settings.n_steps, f"LAMMPS on {ranks} ranks", lambda: logged_step(log))
        if launched and job.show_progress
        else None
    )
    tracked, description = run_on_ranks(job, ranks, job.directory, launcher, progress)
    return ImpactAnalysis.from_tracker(job.model, job.settings, tracked, description)
