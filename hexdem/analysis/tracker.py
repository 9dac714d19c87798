"""Pulse analysis inside the run: an observer of an engine's samples that keeps only what
the outputs need, so that memory grows with the number of beads, never with the run's length.

:class:`PulseTracker` is called with every :class:`~hexdem.engines.sampling.Sample` of a
run (every ``dump_every`` steps, step 0 included) and, at the end, :meth:`PulseTracker.finish`
gives each bead's peak speed, time of peak and half-maximum arrival time with the
definitions of :mod:`hexdem.analysis.peaks`:

* **peak speed** and **time of peak**: the same local cubic spline through the 7 samples
  around the largest one as the dump analysis, so that equal samples give equal peaks;
* **arrival time**: the first time |v| reaches half of the (spline) peak, interpolated
  linearly between the sample before the crossing and the crossing sample (the dump analysis
  uses its spline there; the two differ by a few ns at the default sampling);
* beads whose largest sample is among the last two, or that never moved, get NaN.

It also audits the energy (kinetic + Hertz, minus the work of gravity if any) at about
:data:`ENERGY_SAMPLES` evenly spaced samples, records the speed of a few ``trace_beads`` at
every sample (pulse shapes for the theory), the speed of every bead at the samples
``field_samples`` (wavefront snapshots), and, given a ``threshold_speed``, the first time each
bead's speed reaches it (a second measure of the front, interpolated linearly between samples).

**Several ranks.** Under MPI every rank owns some atoms and sees only those. Each rank keeps
state arrays for all beads but updates only its own; the state of a bead is exact on the
rank that owns it. When atoms change ranks (LAMMPS migrates them when it rebuilds its
neighbour lists) each migrated bead's state is handed from its previous owner to its new one
before the new sample is taken (only those beads' rows travel), at the samples the engine
marks as possibly migrated (:attr:`~hexdem.engines.sampling.Sample.migrated`; LAMMPS: after it
rebuilt its neighbour lists), and only there; :meth:`finish` brings every bead's state from its
owner onto rank 0, which alone returns the results. The energy audit sums each rank's part
(:meth:`~hexdem.analysis.energy.EnergyAudit.part`: its own bodies, with its ghosts for the
contacts that cross ranks) onto rank 0 in one small Reduce per audited sample. The snapshot
fields are merged onto rank 0 at the end.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.analysis.energy import EnergyAudit, energy_error, energy_regions, energy_scale_j
from hexdem.analysis.peaks import refine_peak, refine_peaks
from hexdem.analysis.tracker_kernel import PulseState
from hexdem.engines.sampling import Sample
from hexdem.errors import HexdemError
from hexdem.model.granular import GranularModel, RunSettings

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
    part in (each rank takes part in the same ones; 0 on one rank). ``peak_angular_speed`` (N,) each bead's largest |ω_z| (0 for
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


class PulseTracker:
    """Observer of one run's samples (see the module docstring).

    ``model`` and ``settings`` are the run's (SI model, run units from ``settings.units``);
    ``comm`` the mpi4py communicator of the ranks that share the run (None: one rank);
    ``trace_beads`` bead indices whose every sample is kept; ``field_samples`` sample
    indices at which every bead's speed is kept; ``gravity_m_s2`` the run's uniform gravity;
    ``threshold_speed`` (run units) a speed whose first crossing by each bead is recorded.
    """

    def __init__(self, model: GranularModel, settings: RunSettings, comm=None, trace_beads=(),
                 field_samples=(), gravity_m_s2=None, threshold_speed: float | None = None):
        self.model, self.settings, self.comm = model, settings, comm
        self.root = comm is None or comm.Get_rank() == 0
        n, total = len(model.lattice), settings.n_samples
        self.n_beads, self.n_bodies, self.n_samples_expected = n, model.n_bodies, total
        self.pulses = PulseState(n, RECORD_CAPACITY)
        self.peak_spin = np.zeros(n)
        self.end_velocity = np.zeros((n, 2))
        if threshold_speed is not None and not threshold_speed > 0:
            raise HexdemError(f"the threshold speed must be > 0, got {threshold_speed!r}")
        self.threshold_speed = threshold_speed
        self.threshold_index, self.previous_speed = np.full(n, np.nan), np.zeros(n)
        self.owned = np.zeros(n, dtype=np.bool_)
        self.trace_beads = np.asarray(trace_beads, dtype=np.int64)
        self.traces = np.full((total, len(self.trace_beads)), np.nan)
        self.sensor_beads = np.asarray(model.sensor_beads, dtype=np.int64)
        self.sensor_every = settings.sensor_every
        n_sensed = settings.n_steps // settings.sensor_every + 1 if settings.sensor_every else 0
        self.sensors = np.full((n_sensed, len(self.sensor_beads), 4), np.nan)
        self.field_samples = np.asarray(sorted(field_samples), dtype=np.int64)
        self.fields = np.full((len(self.field_samples), n), np.nan)
        self.rim_fields = np.full((len(self.field_samples) if model.laws.tangential else 0, n), np.nan)
        self.radii = model.lattice.diameters_m[:n] / 2 / settings.units.length_m
        self.energy_every = max(1, (total - 1) // ENERGY_SAMPLES)
        self.audit = EnergyAudit(model, gravity_m_s2)
        self.energies, self.energy_times, self.impact_energy, self.region_energies = [], [], None, []
        self.rotational_energies = []
        self.count = 0
        self.collectives = 0

    def _collective(self, name: str, *args, **kwargs):
        """``comm.<name>(*args, **kwargs)``, counted in :attr:`TrackedPulses.collectives`: every
        collective the analysis takes goes through here."""
        self.collectives += 1
        return getattr(self.comm, name)(*args, **kwargs)

    # ---- state shared across ranks
    def _bead_state(self) -> list[np.ndarray]:
        """Every per-bead array that the bead's owner keeps up to date."""
        return [*self.pulses.arrays(), self.peak_spin, self.threshold_index, self.previous_speed, self.end_velocity]

    def _hand_over(self, owned: np.ndarray) -> None:
        """Give each bead that changed ranks since the last sample (``owned``: this rank's beads
        now) its state from the rank that owned it until now: only those beads' rows travel."""
        arrays = self._bead_state()
        left = np.flatnonzero(self.owned & ~owned)
        arrived = owned & ~self.owned
        for beads, rows in self._collective("allgather", (left, [array[left] for array in arrays])):
            mine = beads[arrived[beads]]
            for array, values in zip(arrays, rows):
                array[mine] = values[arrived[beads]]

    def _collect(self) -> None:
        """Bring every bead's state to rank 0 from its owner for the results; each sample of a
        trace or field was taken by exactly one rank (NaN elsewhere)."""
        from mpi4py import MPI

        arrays = self._bead_state()
        mine = np.flatnonzero(self.owned)
        parts = self._collective("gather", (mine, [array[mine] for array in arrays]), root=0)
        for beads, rows in parts if self.root else ():
            for array, values in zip(arrays, rows):
                array[beads] = values
        for array in (self.traces, self.fields, self.rim_fields, self.sensors):
            taken = np.isfinite(array).astype(np.int64)
            counts = np.empty_like(taken) if self.root else None
            self._collective("Reduce", taken, counts, op=MPI.SUM, root=0)
            self._collective("Reduce", np.nan_to_num(array, nan=0.0), array if self.root else None, op=MPI.SUM,
                             root=0)
            if self.root:
                array[counts == 0] = np.nan

    # ---- observing
    def __call__(self, sample: Sample) -> None:
        s = sample.index
        beads = sample.ids <= self.n_beads
        index = sample.ids[beads] - 1
        speeds = np.hypot(sample.velocities[beads, 0], sample.velocities[beads, 1])
        if self.comm is not None and self.comm.Get_size() > 1:
            if sample.migrated:
                owned = np.zeros(self.n_beads, dtype=np.bool_)
                owned[index] = True
                if s > 0:
                    self._hand_over(owned)
                self.owned = owned
        else:
            self.owned[index] = True
        self.pulses.update(index, speeds, s)
        self.end_velocity[index] = sample.velocities[beads]
        if self.threshold_speed is not None:
            self._cross_threshold(index, speeds, s)
        if sample.angular_velocities is not None:
            self.peak_spin[index] = np.maximum(self.peak_spin[index], np.abs(sample.angular_velocities[beads]))
        if len(self.trace_beads):
            here, rows = self._rows(sample, self.trace_beads)
            self.traces[s, here] = np.hypot(sample.velocities[rows, 0], sample.velocities[rows, 1])
        if self.sensor_every and sample.step % self.sensor_every == 0 and len(self.sensor_beads):
            self._sense(sample)
        if s in self.field_samples:
            self.fields[np.searchsorted(self.field_samples, s), index] = speeds
            if len(self.rim_fields):
                self.rim_fields[np.searchsorted(self.field_samples, s), index] = (
                    np.abs(sample.angular_velocities[beads]) * self.radii[index])
        if s % self.energy_every == 0 or s == self.n_samples_expected - 1:
            self._audit(sample)
        self.count = s + 1

    def _cross_threshold(self, index: np.ndarray, speeds: np.ndarray, s: int) -> None:
        """Record, as a fractional sample index, where each bead's speed first reached the
        threshold (linear between its previous sample and this one; 0 for a bead at it from the start)."""
        fresh = np.isnan(self.threshold_index[index]) & (speeds >= self.threshold_speed)
        if fresh.any():
            beads, now = index[fresh], speeds[fresh]
            before = self.previous_speed[beads]
            self.threshold_index[beads] = np.maximum(s - (now - self.threshold_speed) / (now - before), 0.0)
        self.previous_speed[index] = speeds

    def _rows(self, sample: Sample, beads: np.ndarray):
        """(mask of ``beads`` this rank owns, their rows in ``sample``)."""
        row = np.full(self.n_bodies + 1, -1, dtype=np.int64)
        row[sample.ids] = np.arange(len(sample.ids))
        rows = row[beads + 1]
        return rows >= 0, rows[rows >= 0]

    def _sense(self, sample: Sample) -> None:
        """Velocity and acceleration of the sensor beads this rank owns, at a sensor sample."""
        here, rows = self._rows(sample, self.sensor_beads)
        self.sensors[sample.step // self.sensor_every, here] = np.hstack(
            [sample.velocities[rows], sample.accelerations[rows]])

    def _audit(self, sample: Sample) -> None:
        """This rank's part of the energy audit (its bodies, with its ghosts' positions for the
        contacts that cross to another rank), summed onto rank 0 in one small Reduce."""
        units = self.settings.units
        bodies, positions = sample.ids - 1, sample.positions
        if sample.ghost_ids is not None:
            bodies = np.concatenate([bodies, sample.ghost_ids - 1])
            positions = np.concatenate([positions, sample.ghost_positions])
        angular = None if sample.angular_velocities is None else sample.angular_velocities / units.time_s
        part = self.audit.part(bodies, len(sample.ids), positions * units.length_m,
                               sample.velocities * units.velocity_m_s, angular)
        if self.comm is not None and self.comm.Get_size() > 1:
            from mpi4py import MPI

            whole = np.empty_like(part) if self.root else None
            self._collective("Reduce", part, whole, op=MPI.SUM, root=0)
            part = whole
        if self.root:
            energy, translational, rotational, by_region = part[0], part[1], part[2], part[3:]
            if self.impact_energy is None:
                self.impact_energy = translational + self._displacement_energy_j()
            self.energies.append(float(energy))
            self.region_energies.append(by_region.reshape(len(self.audit.region_names), 2))
            self.rotational_energies.append(float(rotational))
            self.energy_times.append(sample.time)

    def _displacement_energy_j(self) -> float:
        """The contact energy [J] the initial state's displacements add to the packed state's:
        with the kinetic energy, what the run was given (0 without displacements)."""
        state = self.model.initial_state
        if state is None or not state.displacements_m.any():
            return 0.0
        moved = self.model.initial_positions_m()
        packed = moved.copy()
        packed[:len(state.displacements_m)] -= state.displacements_m
        still = np.zeros_like(moved)
        return self.audit(moved, still) - self.audit(packed, still)

    # ---- results
    def finish(self) -> TrackedPulses | None:
        """The results on rank 0 (None on the other ranks); see :class:`TrackedPulses`."""
        if self.comm is not None and self.comm.Get_size() > 1:
            self._collect()
        if not self.root:
            return None
        interval = self.settings.dump_every * self.settings.dt_s / self.settings.units.time_s
        peak, t_peak, arrival, reach = (np.full(self.n_beads, np.nan) for _ in range(4))
        state = self.pulses
        moved = state.peak > 0.0
        peak[~moved] = 0.0
        complete = moved & (state.peak_index <= self.count - 3)
        full = complete & np.isfinite(state.window).all(axis=1)  # the 7 samples: one refinement for all
        offset, peak[full] = refine_peaks(state.window[full], interval)
        t_peak[full] = state.peak_index[full] * interval + offset
        for b in np.flatnonzero(moved):
            if not complete[b]:
                reach[b] = interval * state.first_crossing(b, 0.5 * state.peak[b])
                continue
            if not full[b]:
                index = np.arange(state.peak_index[b] - 3, state.peak_index[b] + 4)
                valid = (index >= 0) & (index < self.count) & np.isfinite(state.window[b])
                t_peak[b], peak[b] = refine_peak(index[valid] * interval, state.window[b, valid])
            arrival[b] = reach[b] = interval * state.first_crossing(b, 0.5 * peak[b])
        scale = energy_scale_j(self.energies, self.impact_energy)
        return TrackedPulses(peak_speed=peak, t_peak=t_peak, arrival_time=arrival, reach_time=reach,
                             energy_drift=energy_error(self.energies, self.impact_energy, self.model.dissipative),
                             energy_lost=(self.energies[0] - self.energies[-1]) / scale,
                             energy_times=np.array(self.energy_times),
                             region_energies=np.array(self.region_energies).reshape(
                                 len(self.energy_times), len(energy_regions(self.model)[0]), 2),
                             n_samples=self.count, trace_beads=self.trace_beads,
                             trace_times=np.arange(self.count) * interval, trace_speeds=self.traces[:self.count],
                             field_times=self.field_samples * interval, field_speeds=self.fields,
                             field_rim_speeds=self.rim_fields, threshold_time=self.threshold_index * interval,
                             sensor_times=np.arange(len(self.sensors)) * self.sensor_every * self.settings.dt_s
                             / self.settings.units.time_s, sensor_states=self.sensors,
                             peak_angular_speed=self.peak_spin, end_velocity=self.end_velocity,
                             rotational_energy_fraction=rotational_share(self.rotational_energies, self.region_energies),
                             collectives=self.collectives)


def rotational_share(rotational_j, region_energies_j) -> float:
    """The largest share of the kinetic and contact energy (the regions' sum) held in rotation,
    over the audited times (0 where there is no energy)."""
    totals = np.array([np.sum(energies) for energies in region_energies_j])
    shares = np.divide(rotational_j, totals, out=np.zeros(len(totals)), where=totals > 0)
    return float(shares.max(initial=0.0))
