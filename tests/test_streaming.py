"""The analysis inside the run against the analysis of a whole record (issue 10's accuracy)."""

import os
import tracemalloc
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import read_csv

from hexdem.analysis.energy import EnergyAudit
from hexdem.analysis.peaks import pulse_times
from hexdem.analysis.tracker import PulseTracker
from hexdem.cli.main import main
from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.sampling import Sample
from hexdem.experiments.parallel import run_on_ranks
from hexdem.experiments.run import RESULT_FILES, simulate
from hexdem.model.config import RunConfig
from hexdem.model.granular import RunSettings
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings


class NoAudit:
    """Synthetic speeds: no mechanics to audit (one region, a constant energy)."""

    region_names = ["all"]

    def part(self, bodies, n_own, positions, velocities, angular_velocities=None):
        return np.array([1.0, 0.0, 0.0, 0.0, 0.0])


def test_streaming_agrees_with_hexdem_analyse_of_the_dump(dumped_run, tmp_path):
    """Same run, two analyses: in the run, and ``hexdem analyse`` of its dump through MDAnalysis.
    Required: peak speed within 1e-4 relative, arrival within 0.1 µs, time of peak within 0.5 µs."""
    out, streamed = dumped_run
    assert main(["analyse", str(out / "deck"), "--out", str(tmp_path)]) == 0
    for name in RESULT_FILES:
        assert (tmp_path / name).stat().st_size > 0
    _, stream_rows = read_csv(out / "peaks.csv")
    _, dump_rows = read_csv(tmp_path / "peaks.csv")
    assert len(stream_rows) == len(dump_rows) == 11 + 2 * 16
    for key, tolerance, relative in (
        ("peak_speed", 1e-4, True),
        ("arrival_time", 1e-7, False),
        ("t_peak", 5e-7, False),
    ):
        a = np.array([float(row[key]) for row in stream_rows])
        b = np.array([float(row[key]) for row in dump_rows])
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
        scale = np.abs(b[np.isfinite(b)]) if relative else 1.0
        assert np.max(np.abs(a - b)[np.isfinite(b)] / scale) < tolerance, key
    assert streamed.tracked is not None


def _synthetic_speeds(times, n_beads, rng):
    """Pulses of Hertz-like shape arriving one after another, a weaker echo later, and noise."""
    arrival = np.linspace(0.1, 0.6, n_beads) + rng.uniform(0, 0.02, n_beads)
    width = rng.uniform(0.04, 0.08, n_beads)
    speeds = np.exp(-(((times[:, None] - arrival) / width) ** 2))
    speeds += rng.uniform(0.2, 0.9, n_beads) * np.exp(-(((times[:, None] - arrival - 0.3) / width) ** 2))
    return speeds * rng.uniform(0.5, 2.0, n_beads) + 1e-9 * rng.random((len(times), n_beads))


@pytest.mark.parametrize("n_samples", [150, 3000])
def test_tracker_reproduces_the_whole_record_definitions(n_samples):
    """Peaks and times of peak equal to the whole-record definitions. Arrivals: the tracker
    interpolates linearly where the record uses a spline, an error of about Δ²|v''|/(8|v'|), a
    few percent of the sample spacing Δ for these pulses (5 to 10 samples wide) and negligible
    at fine sampling, where the ladder of records brackets the crossing within a rung."""
    rng = np.random.default_rng(7)
    times = np.linspace(0.0, 1.2, n_samples)
    model = build_model(RunConfig(edge_beads=4))
    n = len(model.packing)
    speeds = _synthetic_speeds(times, n, rng)
    settings = RunSettings(dt_s=times[1], n_steps=n_samples - 1, dump_every=1)
    tracker = PulseTracker(model, settings)
    tracker.audit = NoAudit()
    ids = np.arange(1, n + 1)
    for s, row in enumerate(speeds):
        tracker(Sample(s, s, times[s], ids, np.zeros((n, 2)), np.column_stack([row, np.zeros(n)])))
    tracked = tracker.finish()
    whole = pulse_times(times, speeds)
    np.testing.assert_allclose(tracked.peak_speed, whole.peak_speed, rtol=1e-12)
    np.testing.assert_allclose(tracked.t_peak, whole.t_peak, rtol=0, atol=1e-12)
    spacing = times[1]
    tolerance = 0.05 if n_samples < 1000 else 0.01
    assert np.max(np.abs(tracked.arrival_time - whole.arrival_time)) < tolerance * spacing


@dataclass(frozen=True)
class MigratingBeads:
    """An MPI job (see :func:`~hexdem.experiments.parallel.run_on_ranks`): the synthetic speeds of
    a 4-per-edge hexagon fed to one tracker across the ranks, every bead handed to a random rank,
    and each rank's beads shuffled, every ``every`` samples, as LAMMPS migrates and sorts atoms
    when it rebuilds its neighbour lists (those samples alone say they may have migrated)."""

    n_samples: int = 300
    every: int = 7

    def __call__(self, comm):
        rng = np.random.default_rng(11)
        times = np.linspace(0.0, 1.2, self.n_samples)
        model = build_model(RunConfig(edge_beads=4))
        n, ranks = len(model.packing), 1 if comm is None else comm.Get_size()
        speeds = _synthetic_speeds(times, n, rng)
        draws = self.n_samples // self.every + 1
        owners = np.repeat(rng.integers(0, ranks, (draws, n)), self.every, axis=0)
        orders = np.repeat([rng.permutation(n) for _ in range(draws)], self.every, axis=0)
        tracker = PulseTracker(
            model,
            RunSettings(dt_s=times[1], n_steps=self.n_samples - 1, dump_every=1),
            comm,
            trace_beads=(0, 5, 17),
            field_samples=(10, 150),
            threshold_speed=0.05,
        )
        tracker.audit = NoAudit()
        rank = 0 if comm is None else comm.Get_rank()
        for s, row in enumerate(speeds):
            ids = orders[s][owners[s][orders[s]] == rank] + 1
            tracker(
                Sample(
                    s,
                    s,
                    times[s],
                    ids,
                    np.zeros((len(ids), 2)),
                    np.column_stack([row[ids - 1], np.zeros(len(ids))]),
                    migrated=s % self.every == 0,
                )
            )
        return tracker.finish(), int(np.sum(owners[1:] != owners[:-1]))


def test_beads_that_change_ranks_keep_their_pulses(tmp_path, monkeypatch):
    """The same speeds, tracked on one rank and on two between which every bead moves at random
    every 7 samples (each bead's state handed over from its last owner): identical results, traces
    and snapshot fields. One collective per such sample and the final gather; none at the other
    samples, audited or not."""
    # the ranks unpickle the job from here, with the hexdem this test imports
    monkeypatch.setenv(
        "PYTHONPATH", os.pathsep.join(filter(None, [str(Path(__file__).parent), os.environ.get("PYTHONPATH")]))
    )
    one, _ = MigratingBeads()(None)
    two, handed_over = run_on_ranks(MigratingBeads(), 2, tmp_path)
    assert handed_over > 500  # about half of 37 beads at each of 42 draws
    assert np.isfinite(one.arrival_time).sum() > 20 and np.isfinite(one.threshold_time).sum() > 20
    for name in (
        "peak_speed",
        "t_peak",
        "arrival_time",
        "reach_time",
        "threshold_time",
        "trace_speeds",
        "field_speeds",
    ):
        np.testing.assert_array_equal(getattr(two, name), getattr(one, name), err_msg=name)
    assert np.isfinite(two.trace_speeds).all() and np.isfinite(two.field_speeds).all()
    assert one.collectives == 0
    assert two.collectives == (300 - 1) // 7 + 1


def test_the_tracker_records_when_each_bead_first_reaches_a_fixed_speed(tmp_path):
    """The threshold's first crossing, from the whole trace of the 0° line, interpolated by hand
    between the samples around it: the same time to round-off (the struck bead: 0)."""
    threshold = 0.01
    analysis = simulate(
        RunConfig(edge_beads=5, engine="reference"), tmp_path, trace_lines=["0"], threshold_speed=threshold
    )
    times, speeds = analysis.line_trace("0")
    for k, bead in enumerate(analysis.results.lines["0"]):
        i = int(np.argmax(speeds[:, k] >= threshold))
        expected = 0.0 if i == 0 else np.interp(threshold, speeds[i - 1 : i + 1, k], times[i - 1 : i + 1])
        assert analysis.tracked.threshold_time[bead] == pytest.approx(expected, rel=1e-12, abs=1e-15)
    assert analysis.tracked.threshold_time[analysis.results.lines["0"][-1]] > 0


def test_memory_does_not_grow_with_the_run_length(tmp_path):
    """Python-side memory (the analysis) of a run twice as long peaks at the same value;
    a whole trajectory of the longer run would take 4 MB more."""
    config = RunConfig(edge_beads=6, duration=2e-4, dump_every=2)
    peaks = []
    for factor in (1, 2):
        tracemalloc.start()
        simulate(config.replace(duration=factor * 2e-4), tmp_path / f"x{factor}")
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    trajectory_growth = 91 * (1000 // 2) * 4 * 8
    assert trajectory_growth > 1.4e6
    assert peaks[1] - peaks[0] < 0.1 * trajectory_growth


def test_one_and_two_ranks_agree_on_arrival_and_energy(default_run, tmp_path):
    one = default_run[1]
    two = simulate(RunConfig(ranks=2), tmp_path)
    assert two.engine["ranks"] == 2
    np.testing.assert_allclose(two.results.arrival_time, one.results.arrival_time, rtol=1e-9)
    assert two.results.energy_drift == pytest.approx(one.results.energy_drift, rel=1e-6)


def test_an_earlier_small_pulse_just_above_half_the_peak_is_the_arrival():
    """A bead first rises to 0.5005, dips, and later peaks at 1.0: its half-maximum arrival is
    on the first rise (sample 7.96), although that record lies within a rung of the next; the
    tracker interpolates linearly at the rounded top of the small pulse (7.80), not 20 samples
    later on the main pulse."""
    model = build_model(RunConfig(edge_beads=2))
    n = len(model.packing)
    series = np.zeros(60)
    series[5:12] = (0.3, 0.45, 0.498, 0.5005, 0.49, 0.3, 0.1)
    series[20:49] = np.sin(np.linspace(0.0, np.pi, 29))
    series[34] = 1.0
    tracker = PulseTracker(model, RunSettings(dt_s=1.0, n_steps=59, dump_every=1))
    tracker.audit = NoAudit()
    for s, v in enumerate(series):
        tracker(
            Sample(s, s, float(s), np.arange(1, n + 1), np.zeros((n, 2)), np.column_stack([np.full(n, v), np.zeros(n)]))
        )
    whole = pulse_times(np.arange(60.0), series[:, None])
    assert whole.arrival_time[0] == pytest.approx(7.96, abs=0.01)
    assert tracker.finish().arrival_time[0] == pytest.approx(whole.arrival_time[0], abs=0.2)


@dataclass(frozen=True)
class GatheredAudit:
    """An MPI job: the default packing struck by a striker (a body of its own region), tracked
    across the ranks, and beside the tracker's audit (each rank's part, summed) the audit of the
    whole state gathered onto rank 0 at the same samples. Rank 0 returns (tracked, gathered
    (T, R, 2) region energies, samples at which atoms may have changed ranks after the first)."""

    directory: Path

    def __call__(self, comm):
        config = RunConfig(impact="striker", duration=3e-4)
        model = build_model(config)
        settings = run_settings(config, model)
        tracker, audit = PulseTracker(model, settings, comm), EnergyAudit(model)
        units, gathered, migrations = settings.units, [], []

        def observe(sample):
            tracker(sample)
            migrations.append(sample.index > 0 and sample.migrated)
            if sample.index % tracker.energy_every and sample.index != tracker.n_samples_expected - 1:
                return
            parts = comm.gather((sample.ids, sample.positions, sample.velocities), root=0)
            if comm.Get_rank() == 0:
                positions, velocities = np.empty((model.n_bodies, 2)), np.empty((model.n_bodies, 2))
                for ids, x, v in parts:
                    positions[ids - 1], velocities[ids - 1] = x, v
                gathered.append(audit.measure(positions * units.length_m, velocities * units.velocity_m_s)[1])

        LammpsEngine().run(model, settings, self.directory, observe, comm, show_progress=False)
        tracked = tracker.finish()
        return None if tracked is None else (tracked, np.array(gathered), sum(migrations))


def test_the_energy_audit_summed_over_ranks_equals_the_gathered_one(tmp_path, monkeypatch):
    """On 3 ranks each rank audits its own bodies, with half of each contact that crosses to another
    rank: the parts' sum equals the audit of the whole gathered state to round-off, region by region
    (the packing and the striker). Collectives: one per sample at which atoms may have changed ranks
    (the first of the run, and after each rebuild of the neighbour lists) and the final gather, which
    brings the ranks' audit parts to be summed: none per audited sample."""
    monkeypatch.setenv(
        "PYTHONPATH", os.pathsep.join(filter(None, [str(Path(__file__).parent), os.environ.get("PYTHONPATH")]))
    )
    tracked, gathered, migrations = run_on_ranks(GatheredAudit(tmp_path / "deck"), 3, tmp_path)
    assert gathered.shape == tracked.region_energies.shape == (len(tracked.energy_times), 2, 2)
    assert np.all(gathered[1:, 0, 1] > 0) and gathered[:, 1, 1].max() > 0, "contacts in both regions"
    np.testing.assert_allclose(tracked.region_energies, gathered, rtol=1e-12, atol=1e-12 * gathered[0].sum())
    assert migrations >= 1
    assert tracked.collectives == migrations + 1


def test_the_dump_carries_each_beads_radius_and_mass_which_mdanalysis_reads(dumped_run):
    """``radius`` for OVITO (true sizes), ``mass`` for MDAnalysis (``atoms.masses``, not guessed
    from the atom type), both of each bead as the model has them (SI units: kg, m)."""
    import MDAnalysis as mda

    out, analysis = dumped_run
    dump = out / "deck" / "dump.lammpstrj"
    with dump.open() as lines:
        header = next(line for line in lines if line.startswith("ITEM: ATOMS")).split()[2:]
    assert header[:4] == ["id", "type", "radius", "mass"]
    assert analysis.settings.units.name == "si"
    universe = mda.Universe(str(dump), format="LAMMPSDUMP", additional_columns=["radius"])
    np.testing.assert_allclose(universe.atoms.masses, analysis.model.masses_kg, rtol=1e-12)
    np.testing.assert_allclose(
        universe.trajectory.ts.data["radius"], analysis.model.packing.diameters_m / 2, rtol=1e-15
    )
