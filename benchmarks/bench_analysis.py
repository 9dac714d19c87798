"""The in-run analysis part by part, per bead per sample: as it was, in NumPy, and compiled.

Usage: python benchmarks/bench_analysis.py [--edges 100,200] [--samples 279] [--quick]

For a hexagon of each of ``--edges`` beads per edge (100: 29,701 beads; 200: 119,401), one rank's
analysis is fed ``--samples`` synthetic samples (the 1e-3 s run's 279 by default), in process: a
pulse spreading from the struck bead at 550 m/s, decaying as r^−0.6, every bead at rest ahead of it
creeping by round-off (1e-17 m/s a sample, as LAMMPS leaves them), positions on the lattice within
1 nm (half the contacts touch). Three ways, one after another on the same samples:

* **before**: the NumPy tracker without the noise floor (every creeping bead takes the path of a
  new maximum, as before round-off stopped counting as motion) and the NumPy audit;
* **NumPy**: today's NumPy code, which defines the kernels' results (:data:`~hexdem.common.kernel_switch.COMPILED`
False);
* **compiled**: today's compiled kernels (:mod:`hexdem.analysis.compiled`), after a warm-up.

Per part, in ns per bead per sample: the **samples** (the driver's full-step positions and
velocities from LAMMPS's (n, 3) arrays, :func:`~hexdem.engines.lammps.driver.full_step`; before,
freed memory went back to the system, now a run keeps it, :mod:`hexdem.common.memory`), the
**tracker** (the observer less its audit), the
**audit** (per audited sample, :data:`~hexdem.analysis.tracker.ENERGY_SAMPLES` of them), the
**gathering** (:meth:`~hexdem.analysis.tracker.PulseTracker.finish`: each bead's results, per bead),
and the **result files** (tables and figures, :func:`~hexdem.experiments.run.write_results`, in s).
The results of the three ways are checked equal (peaks to the bit; before and now differ only
where round-off counted as motion). Whole runs, with LAMMPS's loop beside them: bench_scale.py.
``--quick``: a 20-per-edge hexagon, 60 samples.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
from machine import describe

import hexdem.common.kernel_switch as compiled_module
from hexdem.analysis.impact import ImpactAnalysis
from hexdem.analysis.tracker import PulseTracker
from hexdem.common.memory import keep_freed_memory
from hexdem.engines.lammps.driver import full_step
from hexdem.engines.sampling import Sample
from hexdem.experiments.run import write_results
from hexdem.model.config import RunConfig
from hexdem.model.granular import RunSettings
from hexdem.model.model_builder import build_model

WAYS = ("before", "NumPy", "compiled")
#: Synthetic pulse: front speed [m/s], width [s], decay exponent, round-off creep [m/s per sample].
FRONT_M_S, WIDTH_S, DECAY, CREEP_M_S = 550.0, 4e-5, 0.6, 1e-17


def synthetic_samples(model, n_samples: int, interval_s: float):
    """(positions (N, 2) [m], a function of the sample index giving velocities (N, 2) [m/s])."""
    rng = np.random.default_rng(1)
    positions = model.initial_positions_m() + 1e-9 * rng.standard_normal((model.n_bodies, 2))
    offset = positions - positions[model.struck_beads[0]]
    r = np.hypot(offset[:, 0], offset[:, 1])
    direction = offset / np.maximum(r, 1e-12)[:, None]
    amplitude = 0.4 * np.minimum(1.0, (r / model.packing.diameter_m + 1) ** -DECAY)

    def velocities(s: int) -> np.ndarray:
        t = s * interval_s
        speed = amplitude * np.exp(-(((t - r / FRONT_M_S) / WIDTH_S) ** 2))
        speed = np.where(t < r / FRONT_M_S - 3 * WIDTH_S, CREEP_M_S * s, speed)
        return speed[:, None] * direction

    return positions, velocities


class Timed:
    """The audit of a tracker, timed (the tracker's own time is the rest)."""

    def __init__(self, audit):
        self.audit, self.seconds, self.calls = audit, 0.0, 0

    def part(self, *args):
        start = time.perf_counter()
        result = self.audit.part(*args)
        self.seconds += time.perf_counter() - start
        self.calls += 1
        return result

    def __getattr__(self, name):
        return getattr(self.audit, name)


def measure(model, settings, way: str, samples, out: Path) -> dict:
    """One way's parts (see the module docstring) over ``samples``."""
    compiled_module.COMPILED = way == "compiled"
    tracker = PulseTracker(model, settings)
    if way == "before":
        tracker.floor = 0.0
    tracker.audit = audit = Timed(tracker.audit)
    positions, velocities = samples
    ids = np.arange(1, model.n_bodies + 1)
    order = np.argsort(positions[:, 0] // (10 * model.packing.diameter_m) * 1e6 + positions[:, 1])  # LAMMPS's bins
    atoms = {name: np.zeros((model.n_bodies, 3)) for name in ("x", "v", "f")}  # LAMMPS's per-atom arrays
    atoms["x"][:, :2], masses = positions[order], model.masses_kg[order]
    observed = taken = 0.0
    for s in range(settings.n_samples):
        atoms["v"][:, :2] = velocities(s)[order]
        start = time.perf_counter()
        positions_now, velocities_now = full_step(
            atoms["x"], atoms["v"], atoms["f"], masses, settings.dt_s, way == "compiled"
        )
        taken += time.perf_counter() - start
        sample = Sample(
            s,
            s * settings.dump_every,
            s * settings.dt_s * settings.dump_every,
            ids[order],
            positions_now,
            velocities_now,
            migrated=s == 0,
        )
        start = time.perf_counter()
        tracker(sample)
        observed += time.perf_counter() - start
    start = time.perf_counter()
    tracked = tracker.finish()
    gathered = time.perf_counter() - start
    analysis = ImpactAnalysis.from_tracker(model, settings, tracked, {"name": "synthetic"})
    start = time.perf_counter()
    write_results(RunConfig(), analysis, out, 0.0, {}, lambda message: None)
    written = time.perf_counter() - start
    n, samples_count = len(model.packing), settings.n_samples
    return {
        "samples": taken / (n * samples_count) * 1e9,
        "tracker": (observed - audit.seconds) / (n * samples_count) * 1e9,
        "audit": audit.seconds / (n * audit.calls) * 1e9,
        "gathering": gathered / n * 1e9,
        "result files": written,
        "peaks": tracked.peak_speed,
        "energies": tracked.region_energies,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--edges", default="100,200", help="hexagon edges in beads (default 100,200)")
    parser.add_argument("--samples", type=int, default=279, help="samples fed (default 279, a 1e-3 s run's)")
    parser.add_argument("--quick", action="store_true", help="a 20-per-edge hexagon, 60 samples")
    args = parser.parse_args()
    edges, n_samples = ([20], 60) if args.quick else ([int(e) for e in args.edges.split(",")], args.samples)
    print(f"machine: {describe()}", flush=True)
    rows = []
    for edge in edges:
        model = build_model(RunConfig(edge_beads=edge))
        interval_s = 3.5868e-6
        settings = RunSettings(
            dt_s=interval_s / 7, n_steps=7 * (n_samples - 1), dump_every=7, contact_time_s=20 * interval_s
        )
        samples = synthetic_samples(model, n_samples, interval_s)
        measure(model, settings, "compiled", samples, Path(tempfile.mkdtemp()))  # warm-up: numba, imports, caches
        results = {}
        for way in WAYS:  # before: freed memory returned to the system, as it was; now it is kept, as runs do
            if way != "before":
                keep_freed_memory()
            results[way] = measure(model, settings, way, samples, Path(tempfile.mkdtemp()))
        now, compiled = results["NumPy"], results["compiled"]
        np.testing.assert_array_equal(compiled["peaks"], now["peaks"])
        # the two ways round the overlaps (differences of coordinates) differently: within 1e-9 of the energy
        # the audit's figures are read against (as tests/test_compiled_analysis.py derives)
        np.testing.assert_allclose(compiled["energies"], now["energies"], rtol=0, atol=1e-9 * now["energies"][0].sum())
        rows.append((len(model.packing), results))
        print(f"  measured {len(model.packing):,} beads", flush=True)
    print(
        f"in-run analysis of one rank, {n_samples} synthetic samples: ns per bead per sample "
        "(audit: per audited sample; gathering: per bead, once), result files [s]"
    )
    print(f"{'beads':>9} {'part':>12} " + " ".join(f"{way:>10}" for way in WAYS) + f" {'before / compiled':>17}")
    for beads, results in rows:
        for part in ("samples", "tracker", "audit", "gathering", "result files"):
            values = [results[way][part] for way in WAYS]
            print(
                f"{beads:>9,} {part:>12} "
                + " ".join(f"{v:>10.3g}" for v in values)
                + f" {values[0] / values[2]:>17.1f}"
            )
    print("(the three ways' peaks are equal to the bit where round-off was not motion, energies to round-off)")


if __name__ == "__main__":
    main()
