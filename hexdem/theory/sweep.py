"""The V₀ sweep of Sec. V: the simulations whose peak speeds the scaling laws are fitted to.

Everything is nondimensional (A = d = M = 1, eq. scaling). For each strike angle (0°, 30°)
and each V₀ of the sweep, one ideal lattice without walls is struck (V₀ given to bead 0) and
the peak speed V_n of every bead of the 0° and +30° observation lines is measured
(:mod:`hexdem.analysis.peaks`). One run per strike serves both of its observation lines, that is two
of the four combinations of :mod:`hexdem.theory.scaling`.

**Run design** (:class:`SweepSettings`). The time step is the two-bead Hertz contact time
τ(V₀) over ``steps_per_contact`` and every run lasts ``duration_contacts`` τ(V₀): in units of
τ(V₀) the pulse needs nearly the same time at every V₀ (14.6 τ to peak at bead 12 of the 0°
line). Without walls, the free edges of an uncompressed packing send nothing back (there is
no tension); the hexagon is ``last + 4`` beads per edge so that the line ends stay ahead of
the fitted beads (a larger hexagon gives identical peaks).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from multiprocessing import get_context

import numpy as np

from hexdem.errors import HexdemError
from hexdem.experiments.parallel import run_on_ranks, spread_tasks
from hexdem.theory.scaling import DEFAULT_LAST, Combination, CombinationFit, fit_combination
from hexdem.model.run_settings import contact_time_s

#: Strike angles of the sweep [deg]: each one serves two combinations.
STRIKES_DEG = (0.0, 30.0)
#: Names of the markers that runs of the sweep on MPI ranks leave when they finish.
DONE_PREFIX = "done-"


@dataclass(frozen=True)
class SweepSettings:
    """How the V₀ sweep is simulated (nondimensional V₀).

    ``v0_min``, ``v0_max``, ``n_v0``: evenly spaced V₀; ``last``: the last bead any fit may
    use; ``edge_beads``: hexagon size (None: ``last`` + 4); ``steps_per_contact``: time step
    τ(V₀)/this; ``samples_per_contact``: output samples per τ(V₀); ``duration_contacts``: run
    length in τ(V₀); ``engine``: "reference" or "lammps"; ``workers``: parallel runs;
    ``launcher``: an MPI launcher command (e.g. ``"mpiexec -f hosts"``): the runs then go to
    ``workers`` MPI ranks it starts, on as many machines as it reaches, instead of local
    processes.
    """

    v0_min: float = 0.01
    v0_max: float = 0.30
    n_v0: int = 30
    last: int = DEFAULT_LAST
    edge_beads: int | None = None
    steps_per_contact: int = 140
    samples_per_contact: int = 35
    duration_contacts: float = 16.0
    engine: str = "reference"
    workers: int = 2
    launcher: str | None = None

    def __post_init__(self):
        if not (0 < self.v0_min < self.v0_max and self.n_v0 >= 4):
            raise HexdemError(f"need 0 < v0_min < v0_max and at least 4 values of V0 (the quadratic laws have "
                              f"3 parameters), got {self.v0_min}..{self.v0_max} with {self.n_v0} values")
        if self.steps_per_contact < self.samples_per_contact or self.samples_per_contact < 5:
            raise HexdemError("need steps_per_contact >= samples_per_contact >= 5")
        if self.workers < 1:
            raise HexdemError(f"workers must be >= 1, got {self.workers}")
        if self.last < 3:
            raise HexdemError(f"the last bead of the windows must be >= 3, got {self.last}")

    @property
    def v0(self) -> np.ndarray:
        return np.round(np.linspace(self.v0_min, self.v0_max, self.n_v0), 12)

    @property
    def hexagon_edge(self) -> int:
        return self.edge_beads if self.edge_beads is not None else self.last + 4

    def as_dict(self) -> dict:
        """The settings and the hexagon edge they give (the ``sweep`` entry of ``scaling.json``)."""
        return {**asdict(self), "hexagon_edge": self.hexagon_edge}

    def config(self, v0: float, strike_deg: float):
        """The :class:`~hexdem.model.config.RunConfig` of one run of the sweep."""
        from hexdem.model.config import RunConfig

        base = RunConfig(shape="hexagon", edge_beads=self.hexagon_edge, wall_material="none",
                         units="nondimensional", v0=float(v0), strike_angle_deg=float(strike_deg),
                         engine=self.engine, dump_every=self.steps_per_contact // self.samples_per_contact)
        tau = contact_time_s(base) / base.unit_system.time_s
        return base.replace(dt=tau / self.steps_per_contact, duration=self.duration_contacts * tau)


@dataclass(frozen=True)
class RunPeaks:
    """What one run of the sweep keeps: per observation line (``"0"``, ``"+30"``) the beads'
    ``peaks`` V_n and ``t_peak``, and ``traces`` (times, speeds of the line's beads)."""

    v0: float
    strike_deg: float
    peaks: dict
    t_peak: dict
    traces: dict
    energy_drift: float
    wall_time_s: float


def run_one(settings: SweepSettings, v0: float, strike_deg: float, comm=None) -> RunPeaks:
    """Simulate one V₀ and strike of the sweep in a scratch directory (``comm``: a one-rank
    communicator inside an MPI job, else None)."""
    from hexdem.experiments.run import simulate

    start = time.perf_counter()
    config = settings.config(v0, strike_deg)
    with tempfile.TemporaryDirectory(prefix="hexdem-scaling-") as scratch:
        analysis = simulate(config, scratch, trace_lines=("0", "+30"), comm=comm)
    r = analysis.results
    lines = {name: r.lines[name][:settings.last + 2] for name in ("0", "+30")}
    traces = {}
    for name, beads in lines.items():
        times, speeds = analysis.line_trace(name)
        traces[name] = (times, speeds[:, :len(beads)])
    return RunPeaks(float(v0), float(strike_deg),
                    {name: r.peak_speed[beads] for name, beads in lines.items()},
                    {name: r.t_peak[beads] for name, beads in lines.items()},
                    traces,
                    float(r.energy_drift), time.perf_counter() - start)


@dataclass
class Sweep:
    """Peak speeds of a V₀ sweep: ``runs[(strike_deg, i)]`` the :class:`RunPeaks` of V₀ = v0[i]."""

    settings: SweepSettings
    runs: dict = field(default_factory=dict)
    wall_time_s: float = 0.0

    @property
    def v0(self) -> np.ndarray:
        return self.settings.v0

    def peaks(self, combination: Combination) -> np.ndarray:
        """(K, L) peak speeds V_n along the combination's line for every V₀."""
        rows = [self.runs[(combination.strike_deg, i)].peaks[combination.line] for i in range(len(self.v0))]
        return np.array(rows)

    def fit(self, combination: Combination, last: int | None = None, kind: str = "loglinear") -> CombinationFit:
        peaks = self.peaks(combination)
        last = self.settings.last if last is None else last
        missing = ~np.isfinite(peaks[:, :last + 1])
        if missing.any():
            i, n = np.argwhere(missing)[0]
            raise HexdemError(f"{combination.name}: bead {n} had not peaked at V0 = {self.v0[i]:.4g} within "
                              f"{self.settings.duration_contacts} contact times; raise duration_contacts or "
                              "lower the window's last bead")
        return fit_combination(combination, self.v0, peaks, last, kind)


def run_sweep(settings: SweepSettings, log=None) -> Sweep:
    """All runs of the sweep (both strike angles), ``settings.workers`` at a time, with
    progress on ``log`` (default: stderr)."""
    log = log or (lambda message: print(f"hexdem scaling: {message}", file=sys.stderr, flush=True))
    jobs = [(strike, i, v0) for strike in STRIKES_DEG for i, v0 in enumerate(settings.v0)]
    sweep, start = Sweep(settings), time.perf_counter()
    log(f"{len(jobs)} runs ({settings.engine}, hexagon {settings.hexagon_edge} per edge, no walls, "
        f"{settings.workers} workers)")
    for done, (key, result) in enumerate(_results(settings, jobs), 1):
        sweep.runs[key] = result
        log(f"[{done}/{len(jobs)}] strike {result.strike_deg:g} deg, V0 = {result.v0:.4g}: "
            f"{result.wall_time_s:.1f} s, energy drift {result.energy_drift:.1e}")
    sweep.wall_time_s = time.perf_counter() - start
    return sweep


@dataclass(frozen=True)
class SweepTasks:
    """An MPI job: the sweep's runs ``jobs`` [(strike, i, V₀)] spread over the ranks, one
    engine per rank; each finished run leaves a marker in ``directory`` (for the progress)."""

    settings: SweepSettings
    jobs: tuple
    directory: str

    def __call__(self, comm):
        return spread_tasks(comm, self.jobs, self._run)

    def _run(self, job, alone) -> RunPeaks:
        strike, i, v0 = job
        result = run_one(self.settings, v0, strike, alone)
        open(os.path.join(self.directory, f"{DONE_PREFIX}{strike:g}-{i}"), "w").close()
        return result


def _on_ranks(settings: SweepSettings, jobs):
    """Yield ((strike, i), RunPeaks) of every run, the runs spread over MPI ranks that
    ``settings.launcher`` starts. The runs are handed over in a hidden directory under the
    current one, which ranks on other machines must share (a local /tmp would not be)."""
    with tempfile.TemporaryDirectory(prefix=".hexdem-sweep-", dir=os.getcwd()) as directory:
        def count_done() -> int:
            return sum(name.startswith(DONE_PREFIX) for name in os.listdir(directory))

        results = run_on_ranks(SweepTasks(settings, tuple(jobs), directory), min(settings.workers, len(jobs)),
                               directory, settings.launcher, progress=(len(jobs), "V0 sweep", count_done))
    for (strike, i, _), result in zip(jobs, results):
        yield (strike, i), result


def _results(settings: SweepSettings, jobs):
    """Yield ((strike, i), RunPeaks) as runs finish: on MPI ranks with a launcher, in this
    process for one worker, else in spawned processes (callers' scripts need an
    ``if __name__ == "__main__":`` guard)."""
    if settings.launcher is not None:
        yield from _on_ranks(settings, jobs)
        return
    if settings.workers == 1:
        for strike, i, v0 in jobs:
            yield (strike, i), run_one(settings, v0, strike)
        return
    with ProcessPoolExecutor(max_workers=settings.workers, mp_context=get_context("spawn")) as pool:
        futures = {pool.submit(run_one, settings, v0, strike): (strike, i) for strike, i, v0 in jobs}
        for future in as_completed(futures):
            yield futures[future], future.result()
