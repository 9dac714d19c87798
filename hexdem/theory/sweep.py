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

import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from hexdem.errors import HexdemError, one_line
from hexdem.experiments.executors import holding, parsl_session, run_tasks, study_executor, study_retries, tasks_failed
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import contact_time_s
from hexdem.theory.scaling import DEFAULT_LAST, Combination, CombinationFit, fit_combination

#: Strike angles of the sweep [deg]: each one serves two combinations.
STRIKES_DEG = (0.0, 30.0)


@dataclass(frozen=True)
class SweepSettings:
    """How the V₀ sweep of Sec. V is simulated (nondimensional, A = d = M = 1).

    Attributes
    ----------
    v0_min, v0_max : float
        The smallest and largest striking speed V₀ (nondimensional).
    n_v0 : int
        How many V₀, evenly spaced (at least 4: the quadratic laws have 3 parameters).
    last : int
        The last bead any fit may use.
    edge_beads : int or None
        The hexagon's beads per edge (None: ``last`` + 4).
    steps_per_contact : int
        The time step, τ(V₀) over this, τ the contact time at V₀.
    samples_per_contact : int
        Samples of the beads' speeds per τ(V₀).
    duration_contacts : float
        Each run's length, in τ(V₀).
    engine : {"reference", "lammps"}
        The engine of every run.
    workers : int
        Runs at once, in local processes.
    launcher : str or None
        The MPI launcher command that starts each run's rank (e.g. ``"srun"``; None: in the
        worker's process).
    parsl : str or None
        A Parsl configuration file that takes the runs instead of local processes
        (:mod:`hexdem.experiments.executors`; :func:`run_sweep` runs it).
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
    parsl: str | None = None

    def __post_init__(self):
        if not (0 < self.v0_min < self.v0_max and self.n_v0 >= 4):
            raise HexdemError(
                f"need 0 < v0_min < v0_max and at least 4 values of V0 (the quadratic laws have "
                f"3 parameters), got {self.v0_min}..{self.v0_max} with {self.n_v0} values"
            )
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

        base = RunConfig(
            shape="hexagon",
            edge_beads=self.hexagon_edge,
            wall_material="none",
            units="nondimensional",
            v0=float(v0),
            strike_angle_deg=float(strike_deg),
            engine=self.engine,
            dump_every=self.steps_per_contact // self.samples_per_contact,
            launcher=self.launcher,
        )
        tau = contact_time_s(base, build_model(base)) / base.unit_system.time_s
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
    warnings: tuple[str, ...] = ()


def run_one(settings: SweepSettings, v0: float, strike_deg: float) -> RunPeaks:
    """Simulate one V₀ and strike of the sweep in a scratch directory."""
    from hexdem.experiments.run import simulate

    start = time.perf_counter()
    config = settings.config(v0, strike_deg)
    with tempfile.TemporaryDirectory(prefix="hexdem-scaling-") as scratch:
        analysis = simulate(config, scratch, trace_lines=("0", "+30"))
    r = analysis.results
    lines = {name: r.lines[name][: settings.last + 2] for name in ("0", "+30")}
    traces = {}
    for name, beads in lines.items():
        times, speeds = analysis.line_trace(name)
        traces[name] = (times, speeds[:, : len(beads)])
    t_peak = {name: r.t_peak[beads] for name, beads in lines.items()}
    end = analysis.settings.duration_s / analysis.settings.units.time_s
    tau = config.duration / settings.duration_contacts
    return RunPeaks(
        float(v0),
        float(strike_deg),
        {name: r.peak_speed[beads] for name, beads in lines.items()},
        t_peak,
        traces,
        float(r.energy_drift),
        time.perf_counter() - start,
        window_warnings({name: times[: settings.last + 1] for name, times in t_peak.items()}, end, tau),
    )


#: Warnings of a run of the V₀ sweep, by name: what its fits should not be trusted for.
SCALING_WARNINGS = {
    "window_peak_near_end": "a bead of the fit window peaked within one contact time of the run's end "
    "(or not at all): its peak may be cut short; raise duration_contacts"
}


def window_warnings(t_peak: dict, end: float, contact_time: float) -> tuple[str, ...]:
    """The names (:data:`SCALING_WARNINGS`) of the warnings of a run whose fit-window beads peaked
    at ``t_peak`` ({line: times}) in a run that ended at ``end`` (both in the run's units)."""
    times = np.concatenate(list(t_peak.values()))
    late = ~np.isfinite(times) | (times > end - contact_time)
    return ("window_peak_near_end",) if late.any() else ()


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
        missing = ~np.isfinite(peaks[:, : last + 1])
        if missing.any():
            i, n = np.argwhere(missing)[0]
            raise HexdemError(
                f"{combination.name}: bead {n} had not peaked at V0 = {self.v0[i]:.4g} within "
                f"{self.settings.duration_contacts} contact times; raise duration_contacts or "
                "lower the window's last bead"
            )
        return fit_combination(combination, self.v0, peaks, last, kind)


def run_sweep(settings: SweepSettings, log=None, parsl=None) -> Sweep:
    """All runs of the sweep (both strike angles), ``settings.workers`` at a time, with
    progress on ``log`` (default: stderr); ``parsl``: the
    :class:`~hexdem.experiments.executors.ParslSession` of ``settings.parsl`` when the caller
    has run that file already (None: it runs here)."""
    log = log or (lambda message: print(f"hexdem scaling: {message}", file=sys.stderr, flush=True))
    jobs = [(strike, i, v0) for strike in STRIKES_DEG for i, v0 in enumerate(settings.v0)]
    parsl = parsl_session(settings.parsl if parsl is None else parsl)
    sweep, start = Sweep(settings), time.perf_counter()
    where = f"on Parsl ({settings.parsl})" if settings.parsl is not None else f"{settings.workers} workers"
    log(f"{len(jobs)} runs ({settings.engine}, hexagon {settings.hexagon_edge} per edge, no walls, {where})")
    with holding(parsl, settings.workers):
        for done, (key, result) in enumerate(_results(settings, jobs, parsl), 1):
            sweep.runs[key] = result
            log(
                f"[{done}/{len(jobs)}] strike {result.strike_deg:g} deg, V0 = {result.v0:.4g}: "
                f"{result.wall_time_s:.1f} s, energy drift {result.energy_drift:.1e}"
            )
    sweep.wall_time_s = time.perf_counter() - start
    return sweep


def _results(settings: SweepSettings, jobs, parsl):
    """Yield ((strike, i), RunPeaks) as runs finish, each run a task of the study executor
    (local processes: callers' scripts need an ``if __name__ == "__main__":`` guard; Parsl: the
    session ``parsl``); the runs that failed are named at the end."""
    tasks = {(strike, i): (run_one, settings, v0, strike) for strike, i, v0 in jobs}
    failed, errors = [], []
    with study_executor(min(settings.workers, len(jobs)), parsl) as executor:
        for (strike, i), result, error in run_tasks(executor, tasks, study_retries(parsl)):
            if error is None:
                yield (strike, i), result
            else:
                failed.append(f"strike {strike:g} deg, V0 = {settings.v0[i]:.4g}: {one_line(error)}")
                errors.append(error)
    if failed:
        raise tasks_failed(f"{len(failed)} of {len(jobs)} runs of the V0 sweep failed; {'; '.join(failed)}", errors)
