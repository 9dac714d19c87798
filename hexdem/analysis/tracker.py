"""Pulse analysis inside the run: an observer of an engine's samples that keeps only what
the outputs need, so that memory grows with the number of beads, never with the run's length.

:class:`PulseTracker` is called with every :class:`~hexdem.engines.sampling.Sample` of a
run (every ``dump_every`` steps, step 0 included) and, at the end, :meth:`PulseTracker.finish`
gives each bead's peak speed, time of peak and half-maximum arrival time with the
definitions of :mod:`hexdem.analysis.peaks`:

* **peak speed** and **time of peak**: the same largest maximum of the local cubic splines
  through the 7 samples around the largest one and around each rival local maximum as the dump
  analysis, so that equal samples give equal peaks;
* **arrival time**: the first time |v| reaches half of the (spline) peak, interpolated
  linearly between the sample before the crossing and the crossing sample (the dump analysis
  uses its spline there; the two differ by a few ns at the default sampling);
* beads whose largest sample is among the last two, or that never moved, get NaN.

It also audits the energy (kinetic + Hertz, minus the work of gravity if any) at about
:data:`ENERGY_SAMPLES` evenly spaced samples, records the speed of a few ``trace_beads`` at
every sample (pulse shapes for the theory), the speed of every bead at the samples
``field_samples`` (wavefront snapshots), and, given a ``threshold_speed``, the first time each
bead's speed reaches it (a second measure of the front, interpolated linearly between samples).

**Several ranks.** Under MPI every rank owns some atoms and sees only those, and keeps state
for those beads only, one row each, in the order of the engine's samples, so that per-rank memory
follows the rank's own beads. When atoms change ranks (LAMMPS migrates them, and reorders them,
only when it rebuilds its neighbour lists, which a sample says:
:attr:`~hexdem.engines.sampling.Sample.migrated`), the rows are laid out anew before the sample
is taken: the beads a rank kept keep their rows, and each bead that left hands its row to its new
owner in one collective (only those beads' rows travel). A sample at which nothing can have
migrated takes no collective, and neither does the energy audit: each rank keeps its part
(:meth:`~hexdem.analysis.energy.EnergyAudit.part`: its own bodies, with its ghosts for the
contacts that cross ranks) of each audited sample (a Reduce per audited sample made every rank
wait there for the slowest). :meth:`finish` works out each bead's results on its owner and
gathers them, with the traces, sensors, snapshot fields and audit parts each rank took, onto rank
0 in one collective, where the parts are summed; rank 0 alone returns the results.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from hexdem.analysis.compiled import BodiesReordered, bind_pulses, sample_pulses
from hexdem.analysis.energy import EnergyAudit, energy_error, energy_scale_j, rotational_share
from hexdem.analysis.peaks import noise_floor, refine_peak, refine_peaks
from hexdem.analysis.tracker_kernel import PulseState
from hexdem.common.kernel_switch import runs_compiled
from hexdem.common.preload import load_in_background
from hexdem.engines.sampling import Sample
from hexdem.errors import HexdemError
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.units import in_si

#: About this many evenly spaced samples enter the energy audit (the first and last always).
ENERGY_SAMPLES = 100
#: Records of the running maximum kept per bead for the arrival time (see tracker_kernel): 8
#: arrays of this many per bead, 2 kB. Arrivals are bit-identical to 64 slots on the default run,
#: a striker, a precompressed packing, a half-hexagon and a slow 30° strike (16 slots differ on the
#: precompressed one, whose long precursor climbs in many small steps).
RECORD_CAPACITY = 32


@dataclass(frozen=True)
class TrackedPulses:
    """What a :class:`PulseTracker` found, in the run's unit system.

    Per bead (N,): ``peak_speed``, ``t_peak``, ``arrival_time``, ``reach_time`` (see
    :mod:`hexdem.analysis.peaks`).
    ``energy_drift`` the audit's error over ``energy_times`` (see
    :func:`~hexdem.analysis.energy.energy_error`); ``energy_lost`` (E0 − E_end) relative to the
    impact's kinetic energy; ``region_energies`` (len(energy_times), R, 2) the kinetic and contact
    energy [J] of each region (:func:`~hexdem.analysis.energy.energy_regions`) at those times;
    ``n_samples``;
    ``trace_times`` (S,) and ``trace_speeds`` (S, len(trace_beads));
    ``threshold_time`` (N,) when each bead's speed first reached the tracker's ``threshold_speed``
    (NaN: never, or no threshold asked for); ``field_times`` (F,) and
    ``field_speeds`` (F, N) at the requested snapshot samples, and ``field_rim_speeds`` (F, N)
    there, each bead's |ω_z| r, the speed its rim turns at (empty, (0, N), for spheres that do
    not turn); ``sensor_times`` (K,) and
    ``sensor_states`` (K, n_sensors, 4): vx, vy, ax, ay of the model's sensor beads every
    ``settings.sensor_every`` steps. ``collectives`` the MPI collective operations the tracker took
    part in (each rank takes part in the same ones; 0 on one rank). ``analysis_cpu_s`` the CPU time [s]
    of each part of the analysis, summed over the ranks: ``tracker`` (each sample's update),
    ``audit`` (the energy audit), ``gathering`` (each bead's results at the end). ``peak_angular_speed`` (N,) each
    bead's largest |ω_z| (0 for
    spheres that do not turn); ``rotational_energy_fraction`` the largest share of the kinetic and
    contact energy held in rotation at the audited times; ``end_velocity`` (N, 2) each bead's
    velocity at the last sample (a rebound's outgoing velocity).
    """

    peak_speed: np.ndarray
    t_peak: np.ndarray
    arrival_time: np.ndarray
    reach_time: np.ndarray
    energy_drift: float
    energy_lost: float
    energy_times: np.ndarray
    region_energies: np.ndarray
    n_samples: int
    trace_beads: np.ndarray
    trace_times: np.ndarray
    trace_speeds: np.ndarray
    field_times: np.ndarray
    field_speeds: np.ndarray
    field_rim_speeds: np.ndarray
    threshold_time: np.ndarray
    sensor_times: np.ndarray
    sensor_states: np.ndarray
    peak_angular_speed: np.ndarray
    rotational_energy_fraction: float
    end_velocity: np.ndarray
    collectives: int = 0
    analysis_cpu_s: dict = field(default_factory=dict)


class PulseTracker:
    """Observer of one run's samples (see the module docstring).

    ``model`` and ``settings`` are the run's (SI model, run units from ``settings.units``);
    ``comm`` the mpi4py communicator of the ranks that share the run (None: one rank);
    ``trace_beads`` bead indices whose every sample is kept; ``field_samples`` sample
    indices at which every bead's speed is kept; ``gravity_m_s2`` the run's uniform gravity;
    ``threshold_speed`` (run units) a speed whose first crossing by each bead is recorded.
    """

    def __init__(
        self,
        model: GranularModel,
        settings: RunSettings,
        comm=None,
        trace_beads=(),
        field_samples=(),
        gravity_m_s2=None,
        threshold_speed: float | None = None,
    ):
        self.model, self.settings, self.comm = model, settings, comm
        self.root = comm is None or comm.Get_rank() == 0
        self.several = comm is not None and comm.Get_size() > 1
        total = settings.n_samples
        self.n_beads, self.n_samples_expected = len(model.packing), total
        if threshold_speed is not None and not threshold_speed > 0:
            raise HexdemError(f"the threshold speed must be > 0, got {threshold_speed!r}")
        self.threshold_speed = threshold_speed
        self.floor = run_noise_floor(model, settings)
        self.sample_ids, self.ids = None, np.zeros(0, dtype=np.int64)  # (no sample yet)
        self.compiled = runs_compiled()
        self._start_rows(0)
        self.trace_beads = np.asarray(trace_beads, dtype=np.int64)
        self.traces = np.full((total, len(self.trace_beads)), np.nan)
        self.sensor_beads = np.asarray(model.sensor_beads, dtype=np.int64)
        self.sensor_every = settings.sensor_every
        n_sensed = settings.n_steps // settings.sensor_every + 1 if settings.sensor_every else 0
        self.sensors = np.full((n_sensed, len(self.sensor_beads), 4), np.nan)
        self.field_samples = np.asarray(sorted(field_samples), dtype=np.int64)
        self.field_set = frozenset(self.field_samples.tolist())
        self.field_parts = []
        self.energy_every = max(1, (total - 1) // ENERGY_SAMPLES)
        if not self.compiled:  # the NumPy audit's pair search, while the engine starts
            load_in_background("scipy.spatial")
        self.audit = EnergyAudit(model, gravity_m_s2, self.compiled)
        self.audit_bodies = None  # the bodies of this rank's audited rows, own then ghosts, since the last migration
        self.energy_times, self.audit_parts = [], []
        self.count = 0
        self.collectives = 0
        self.cpu_s = {"tracker": 0.0, "audit": 0.0, "gathering": 0.0}  # this rank's thread CPU time per part

    def _collective(self, name: str, *args, **kwargs):
        """``comm.<name>(*args, **kwargs)``, counted in :attr:`TrackedPulses.collectives`: every
        collective the analysis takes goes through here."""
        self.collectives += 1
        return getattr(self.comm, name)(*args, **kwargs)

    # ---- this rank's beads
    def _start_rows(self, n: int) -> None:
        """State for ``n`` beads as before their first sample."""
        self.pulses = PulseState(n, RECORD_CAPACITY, self.floor)
        self.pulse_arrays = bind_pulses(self.pulses) if self.compiled else None
        self.peak_spin, self.end_velocity = np.zeros(n), np.zeros((n, 2))
        self.threshold_index, self.previous_speed = np.full(n, np.nan), np.zeros(n)

    def _bead_state(self) -> list[np.ndarray]:
        """Every per-bead array, row by row this rank's beads (:attr:`ids`)."""
        return [*self.pulses.arrays(), self.peak_spin, self.threshold_index, self.previous_speed, self.end_velocity]

    def _rows_of(self, ids: np.ndarray, among: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(mask of ``ids`` found in ``among``, their positions there)."""
        if not len(among):
            return np.zeros(len(ids), dtype=np.bool_), np.zeros(0, dtype=np.int64)
        order = np.argsort(among)
        at = np.minimum(np.searchsorted(among, ids, sorter=order), len(among) - 1)
        found = among[order[at]] == ids
        return found, order[at[found]]

    def _arrange(self, sample: Sample) -> None:
        """Lay this rank's rows out as its beads in ``sample`` (possibly migrated, see
        :attr:`~hexdem.engines.sampling.Sample.migrated`): the beads it kept keep their state, those
        that left hand theirs to the other ranks in one collective (only their rows travel), and
        those that arrived take it from there. A rank whose bodies are those of its previous sample, in
        the same order, keeps its rows as they are (and hands nothing over)."""
        if self.sample_ids is not None and np.array_equal(sample.ids, self.sample_ids):
            if self.several and sample.index > 0:  # the others may hand their beads over to each other
                self._collective("allgather", (self.ids[:0], []))
            return
        beads = np.flatnonzero(sample.ids <= self.n_beads)
        ids = sample.ids[beads]
        kept, rows = self._rows_of(ids, self.ids)
        left = np.ones(len(self.ids), dtype=np.bool_)
        left[rows] = False
        old = self._bead_state()
        self._start_rows(len(ids))
        new = self._bead_state()
        for array, values in zip(new, old):
            array[kept] = values[rows]
        if self.several and sample.index > 0:
            arrived = np.flatnonzero(~kept)
            missing = np.ones(len(arrived), dtype=np.bool_)
            for their_ids, their_rows in self._collective("allgather", (self.ids[left], [a[left] for a in old])):
                found, at = self._rows_of(ids[arrived], their_ids)
                missing &= ~found
                for array, values in zip(new, their_rows):
                    array[arrived[found]] = values[at]
            if missing.any():
                raise HexdemError(
                    f"bead {ids[arrived[missing]][0]} came to rank {self.comm.Get_rank()} at sample "
                    f"{sample.index} from no rank: its pulse state is lost"
                )
        self.sample_ids, self.bead_rows, self.ids = sample.ids.copy(), beads, ids
        self.trace_here, self.trace_rows = self._rows_of(self.trace_beads + 1, ids)
        self.sensors_here, self.sensor_rows = self._rows_of(self.sensor_beads + 1, ids)

    # ---- observing
    def __call__(self, sample: Sample) -> None:
        start, audited = time.thread_time(), self.cpu_s["audit"]
        self._observe(sample)
        self.cpu_s["tracker"] += time.thread_time() - start - (self.cpu_s["audit"] - audited)

    def _observe(self, sample: Sample) -> None:
        s = sample.index
        if sample.migrated:
            self._arrange(sample)
            self.audit_bodies = None
        speeds = self._take_sample(sample)
        if self.threshold_speed is not None:
            self._cross_threshold(np.arange(len(self.ids)), speeds, s)
        spins = None if sample.angular_velocities is None else np.abs(sample.angular_velocities[self.bead_rows])
        if spins is not None:
            np.maximum(self.peak_spin, spins, out=self.peak_spin)
        if len(self.trace_beads):
            self.traces[s, self.trace_here] = (
                np.hypot(*self.end_velocity[self.trace_rows].T) if speeds is None else speeds[self.trace_rows]
            )
        if self.sensor_every and sample.step % self.sensor_every == 0 and len(self.sensor_beads):
            rows = self.bead_rows[self.sensor_rows]
            self.sensors[sample.step // self.sensor_every, self.sensors_here] = np.hstack(
                [sample.velocities[rows], sample.accelerations[rows]]
            )
        if s in self.field_set:
            radii = self.model.packing.diameters_m[self.ids - 1] / 2 / self.settings.units.length_m
            rims = spins * radii if self.model.laws.tangential else None
            self.field_parts.append((np.searchsorted(self.field_samples, s), self.ids, speeds, rims))
        if s % self.energy_every == 0 or s == self.n_samples_expected - 1:
            self._audit(sample)
        self.count = s + 1

    def _take_sample(self, sample: Sample) -> np.ndarray | None:
        """Take ``sample`` into the pulse state once its bodies are found to be the previous sample's, in order
        (laid out by :meth:`_arrange` where it says they may have migrated); their velocities become the beads'
        last seen (:attr:`end_velocity`). Returns the beads' speeds; compiled (one pass,
        :func:`~hexdem.analysis.compiled.sample_pulses`, which takes most speeds only when the tracker needs
        them) None, unless the whole sample's are wanted (a threshold's crossings, a speed field)."""
        s = sample.index
        if not self.compiled:
            if not np.array_equal(sample.ids, self.sample_ids):
                raise self._reordered(sample)
            self.end_velocity[:] = sample.velocities[self.bead_rows]
            speeds = np.hypot(self.end_velocity[:, 0], self.end_velocity[:, 1])
            self.pulses.update(np.arange(len(self.ids)), speeds, s)
            return speeds
        wanted = self.threshold_speed is not None or s in self.field_set
        speeds = np.empty(len(self.ids) if wanted else 0)
        try:
            self.pulses.challenge(
                sample_pulses(
                    self.pulse_arrays,
                    ids=np.asarray(sample.ids, np.int64),
                    s=s,
                    speeds=speeds,
                    previous_ids=self.sample_ids,
                    velocities=sample.velocities,
                    rows=self.bead_rows,
                    end_velocity=self.end_velocity,
                )
            )
        except BodiesReordered:
            raise self._reordered(sample) from None
        return speeds if wanted else None

    def _reordered(self, sample: Sample) -> HexdemError:
        """The error for ``sample``, whose bodies are not the previous sample's, in order."""
        return HexdemError(
            f"sample {sample.index} reordered the bodies of rank "
            f"{0 if self.comm is None else self.comm.Get_rank()} without saying that they may have migrated"
        )

    def _cross_threshold(self, index: np.ndarray, speeds: np.ndarray, s: int) -> None:
        """Record, as a fractional sample index, where each bead's speed first reached the
        threshold (linear between its previous sample and this one; 0 for a bead at it from the start)."""
        fresh = np.isnan(self.threshold_index[index]) & (speeds >= self.threshold_speed)
        if fresh.any():
            beads, now = index[fresh], speeds[fresh]
            before = self.previous_speed[beads]
            self.threshold_index[beads] = np.maximum(s - (now - self.threshold_speed) / (now - before), 0.0)
        self.previous_speed[index] = speeds

    def _audit(self, sample: Sample) -> None:
        """This rank's part of the energy audit (its bodies, with its ghosts' positions for the
        contacts that cross to another rank), kept until :meth:`finish` sums the ranks' parts."""
        start = time.thread_time()
        units = self.settings.units
        ghosts = sample.ghost_ids is not None and len(sample.ghost_ids) > 0
        if self.audit_bodies is None:  # (the same array until the bodies may have migrated, see EnergyAudit.part)
            self.audit_bodies = (np.concatenate([sample.ids, sample.ghost_ids]) if ghosts else sample.ids) - 1
        positions = np.concatenate([sample.positions, sample.ghost_positions]) if ghosts else sample.positions
        angular = None if sample.angular_velocities is None else sample.angular_velocities / units.time_s
        self.audit_parts.append(
            self.audit.part(
                self.audit_bodies,
                len(sample.ids),
                in_si(positions, units.length_m),
                in_si(sample.velocities, units.velocity_m_s),
                angular,
            )
        )
        self.energy_times.append(sample.time)
        self.cpu_s["audit"] += time.thread_time() - start

    def _displacement_energy_j(self) -> float:
        """The contact energy [J] the initial state's displacements add to the packed state's:
        with the kinetic energy, what the run was given (0 without displacements)."""
        state = self.model.initial_state
        if state is None or not state.displacements_m.any():
            return 0.0
        moved = self.model.initial_positions_m()
        packed = moved.copy()
        packed[: len(state.displacements_m)] -= state.displacements_m
        still = np.zeros_like(moved)
        return self.audit(moved, still) - self.audit(packed, still)

    # ---- results
    def _own_results(self) -> np.ndarray:
        """(n, 8) per bead of this rank (:attr:`ids`): peak speed, time of peak, arrival and reach
        times, threshold time, largest |ω_z|, last velocity (vx, vy)."""
        interval = self.settings.dump_every * self.settings.dt_s / self.settings.units.time_s
        peak, t_peak, arrival, reach = (np.full(len(self.ids), np.nan) for _ in range(4))
        state = self.pulses
        moved = state.peak_index >= 0
        peak[~moved] = 0.0
        complete = moved & (state.peak_index <= self.count - 3)
        full = complete & np.isfinite(state.window).all(axis=1)  # the 7 samples: one refinement for all
        offset, peak[full] = refine_peaks(state.window[full], interval)
        t_peak[full] = state.peak_index[full] * interval + offset
        for b in np.flatnonzero(complete & ~full):
            index = np.arange(state.peak_index[b] - 3, state.peak_index[b] + 4)
            valid = (index >= 0) & (index < self.count) & np.isfinite(state.window[b])
            t_peak[b], peak[b] = refine_peak(index[valid] * interval, state.window[b, valid])
        rival = complete & (state.best_peak > peak)  # a larger maximum than the largest sample's
        peak[rival] = state.best_peak[rival]
        t_peak[rival] = state.best_index[rival] * interval + state.best_offset[rival] * interval
        for b in np.flatnonzero(moved):
            level = 0.5 * (peak[b] if complete[b] else state.peak[b])
            reach[b] = interval * state.first_crossing(b, level)
            if complete[b]:
                arrival[b] = reach[b]
        return np.column_stack(
            [peak, t_peak, arrival, reach, self.threshold_index * interval, self.peak_spin, self.end_velocity]
        )

    def finish(self) -> TrackedPulses | None:
        """The results on rank 0 (None on the other ranks); see :class:`TrackedPulses`. Each rank
        works out its own beads' results; rank 0 gathers them, with the traces, sensors, snapshot
        fields and audit parts each rank took, in one collective, and sums the audit parts."""
        start = time.thread_time()
        own = self._own_results()
        self.cpu_s["gathering"] = time.thread_time() - start
        audited = np.array(self.audit_parts).reshape(len(self.energy_times), -1)
        mine = (self.ids, own, self.traces, self.sensors, self.field_parts, audited, self.cpu_s)
        parts = self._collective("gather", mine, root=0) if self.several else [mine]
        if not self.root:
            return None
        beads = np.full((self.n_beads, 8), np.nan)
        traces, sensors = self.traces, self.sensors
        fields = np.full((len(self.field_samples), self.n_beads), np.nan)
        rim_fields = np.full((len(self.field_samples) if self.model.laws.tangential else 0, self.n_beads), np.nan)
        sums = np.zeros_like(audited)  # the ranks' audit parts, summed in rank order
        cpu_s = dict.fromkeys(self.cpu_s, 0.0)
        for ids, results, their_traces, their_sensors, their_fields, their_audit, their_cpu_s in parts:
            sums += their_audit
            cpu_s = {part: cpu_s[part] + seconds for part, seconds in their_cpu_s.items()}
            beads[ids - 1] = results
            traces = np.where(np.isnan(traces), their_traces, traces)
            sensors = np.where(np.isnan(sensors), their_sensors, sensors)
            for slot, field_ids, speeds, rims in their_fields:
                fields[slot, field_ids - 1] = speeds
                if rims is not None:
                    rim_fields[slot, field_ids - 1] = rims
        interval = self.settings.dump_every * self.settings.dt_s / self.settings.units.time_s
        energies, translational, rotational = sums[:, 0], sums[:, 1], sums[:, 2]
        region_energies = sums[:, 3:].reshape(len(self.energy_times), len(self.audit.region_names), 2)
        impact_energy = translational[0] + self._displacement_energy_j()
        scale = energy_scale_j(energies, impact_energy)
        return TrackedPulses(
            peak_speed=beads[:, 0],
            t_peak=beads[:, 1],
            arrival_time=beads[:, 2],
            reach_time=beads[:, 3],
            energy_drift=energy_error(energies, impact_energy, self.model.dissipative),
            energy_lost=(energies[0] - energies[-1]) / scale,
            energy_times=np.array(self.energy_times),
            region_energies=region_energies,
            n_samples=self.count,
            trace_beads=self.trace_beads,
            trace_times=np.arange(self.count) * interval,
            trace_speeds=traces[: self.count],
            field_times=self.field_samples * interval,
            field_speeds=fields,
            field_rim_speeds=rim_fields,
            threshold_time=beads[:, 4],
            sensor_times=np.arange(len(sensors)) * self.sensor_every * self.settings.dt_s / self.settings.units.time_s,
            sensor_states=sensors,
            peak_angular_speed=beads[:, 5],
            end_velocity=beads[:, 6:8],
            rotational_energy_fraction=rotational_share(rotational, region_energies),
            collectives=self.collectives,
            analysis_cpu_s=cpu_s,
        )


def run_noise_floor(model: GranularModel, settings: RunSettings) -> float:
    """The run's :func:`~hexdem.analysis.peaks.noise_floor` in its units: round-off relative to the
    fastest body at t = 0 (an impact's V₀, or the initial state's fastest bead)."""
    fastest_m_s = float(np.max(np.linalg.norm(model.initial_velocities_m_s(), axis=1), initial=0.0))
    return noise_floor(fastest_m_s / settings.units.velocity_m_s)
