"""Speed of Sec. VI's work: the default ensemble now and before, and the half-hexagon snapshot run on one vs two ranks.

Usage: python benchmarks/bench_ensemble.py [--workers 2] [--repeats 3] [--before REV] [--skip-ensemble]
       [--skip-ranks] [--quick]

1. ``hexdem ensemble`` with its defaults (20 realizations x 0.25, 0.40, 0.70 m/s, 11 per
   edge, 140 steps per contact) in a fresh directory, with today's hexdem and with hexdem as
   it was at ``--before`` (default e8fb865, the last commit before the speed work; skipped
   when this clone lacks it), one after the other: wall time, and per phase (compact, settle,
   impacts; the impacts are analysed inside their runs) as each run recorded it, and LAMMPS's
   own time for settling a realization vs one impact. Targets: today's <= 60 s on 2 cores, and
   at least 1.5 x faster than before.
2. The half-hexagon of Fig. 4 (91/46, 3151 beads + striker, 0.4 m/s, the snapshot run's
   time step and length, fields taken at its 6 snapshot times inside the run): hexdem's
   ``take_snapshots`` on one rank (in-process) and two ranks (mpiexec), and bare
   ``mpiexec -n N lmp -in in.nooutput`` of the same deck without output, alternately, so
   that all see the same machine load. Prints the wall time (hexdem's includes starting
   the MPI job), LAMMPS's wall time inside hexdem, its "Loop time", and atom-steps/s.
   Target: two ranks >= 1.6 x one rank.

``--quick``: a 2-realization ensemble of 4-per-edge hexagons struck at one speed on one worker,
and the snapshot run on a 5-per-edge hexagon up to 0.1 ms, one repeat (the same code paths,
seconds).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from baseline import BEFORE, baseline_tree, hexdem_command, hexdem_env
from harness import NOOUTPUT_NAME, nooutput_deck
from machine import describe

from hexdem.disorder.runner import MANIFEST_NAME
from hexdem.engines.lammps.runner import run_bare
from hexdem.engines.lammps.standalone import loop_time_s
from hexdem.experiments.snapshots import DEFAULT_TIMES_MS, snapshot_config, take_snapshots
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

ENSEMBLE_TARGET_S = 60.0
ENSEMBLE_SPEED_UP_TARGET = 1.5
SPEED_UP_TARGET = 1.6
QUICK_ENSEMBLE = ("--realizations", "2", "--velocities", "0.4", "--edge-beads", "4")
SNAPSHOT_RUN = (
    RunConfig(shape="half-hexagon", impact="striker", v0=0.4),
    tuple(t * 1e-3 for t in DEFAULT_TIMES_MS["half-hexagon"]),
)
QUICK_SNAPSHOT_RUN = (RunConfig(shape="hexagon", edge_beads=5, impact="striker", v0=0.4), (0.05e-3, 0.1e-3))


def quiet(message: str) -> None:
    pass


def ensemble(work: Path, workers: int, options, name: str, tree: Path | None) -> tuple[float, dict]:
    """(wall time [s], manifest) of ``hexdem ensemble OPTIONS --workers N`` with the version
    unpacked at ``tree`` (None: today's), in a fresh directory."""
    out = work / f"ensemble-{name}"
    start = time.perf_counter()
    done = subprocess.run(
        hexdem_command("ensemble", "--out", str(out), "--workers", str(workers), *options),
        cwd=work,
        env=hexdem_env(tree),
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode:
        raise SystemExit(f"hexdem ensemble ({name}) failed:\n{done.stderr[-3000:]}")
    return time.perf_counter() - start, json.loads((out / MANIFEST_NAME).read_text())


def bench_ensemble(work: Path, workers: int, options, before: str) -> None:
    versions = {"now": None, f"{before} (before)": baseline_tree(work, before)}
    if versions[f"{before} (before)"] is None:
        print(f"(this clone lacks {before}: today's hexdem only)")
        del versions[f"{before} (before)"]
    runs = {name: ensemble(work, workers, options, name.split()[0], tree) for name, tree in versions.items()}
    print(
        f"ensemble: hexdem ensemble "
        f"{' '.join(options) or '(defaults: 20 realizations x 3 striker speeds, 11 per edge)'}"
        f" --workers {workers}"
    )
    print(
        f"  {'version':<18} {'wall [s]':>9} "
        + " ".join(f"{phase:>9}" for phase in runs["now"][1]["this_run"]["wall_time_s"])
        + f" {'LAMMPS settle / impact per run [s]':>36}"
    )
    for name, (total, manifest) in runs.items():
        lammps = manifest["lammps_time_s"]
        print(
            f"  {name:<18} {total:>9.2f} "
            + " ".join(f"{seconds:>9.2f}" for seconds in manifest["this_run"]["wall_time_s"].values())
            + f" {lammps['settle_per_realization']:>17.2f} / {lammps['impact_per_run']:<16.2f}"
        )
    total = runs["now"][0]
    print(f"  target <= {ENSEMBLE_TARGET_S:g} s: {'met' if total <= ENSEMBLE_TARGET_S else 'NOT met'} ({total:.1f} s)")
    for name, (seconds, _) in runs.items():
        if name != "now":
            speed_up = seconds / total
            print(
                f"  before / now: {speed_up:.2f} x; target >= {ENSEMBLE_SPEED_UP_TARGET:g}: "
                f"{'met' if speed_up >= ENSEMBLE_SPEED_UP_TARGET else 'NOT met'}",
                flush=True,
            )


def bench_ranks(work: Path, repeats: int, base: RunConfig, times_s) -> None:
    model = build_model(base)
    config = snapshot_config(base, model, sorted(times_s))
    settings = run_settings(config, model)
    atom_steps = model.n_bodies * settings.n_steps
    runners = [(f"hexdem, {ranks} rank{'s' * (ranks > 1)}", "hexdem", ranks) for ranks in (1, 2)]
    runners += [(f"bare lmp, {ranks} rank{'s' * (ranks > 1)}", "bare", ranks) for ranks in (1, 2)]
    decks = {ranks: nooutput_deck(model, settings, work / f"bare{ranks}") for ranks in (1, 2)}
    times = {name: {"wall": [], "lammps": [], "loop": []} for name, _, _ in runners}
    for repeat in range(repeats):
        for name, kind, ranks in runners:
            if kind == "hexdem":
                directory = work / f"hexdem{ranks}-{repeat}"
                start = time.perf_counter()
                engine = take_snapshots(base.replace(ranks=ranks), model, times_s, directory).engine
                times[name]["wall"].append(time.perf_counter() - start)
                times[name]["lammps"].append(engine["wall_time_s"])
                times[name]["loop"].append(loop_time_s(directory / "log.lammps"))
                shutil.rmtree(directory)
            else:
                info = run_bare(decks[ranks], ranks, NOOUTPUT_NAME)
                times[name]["wall"].append(info.wall_time_s)
                times[name]["lammps"].append(info.wall_time_s)
                times[name]["loop"].append(loop_time_s(decks[ranks].log_path))
    print(
        f"snapshot run, {model.packing.shape}: {model.n_bodies} atoms x {settings.n_steps} steps, "
        f"{len(times_s)} fields; median of {repeats} alternating run(s)"
    )
    print(f"  {'runner':<18} {'wall [s]':>9} {'LAMMPS [s]':>11} {'loop [s]':>9} {'M atom-steps/s (loop)':>22}")
    median = {name: {key: statistics.median(values) for key, values in t.items()} for name, t in times.items()}
    for name, m in median.items():
        print(
            f"  {name:<18} {m['wall']:>9.2f} {m['lammps']:>11.2f} {m['loop']:>9.2f} "
            f"{atom_steps / m['loop'] / 1e6:>22.2f}"
        )
    for kind in ("hexdem", "bare lmp"):
        one, two = median[f"{kind}, 1 rank"], median[f"{kind}, 2 ranks"]
        speed_up = one["loop"] / two["loop"]
        print(
            f"  {kind}: 2 ranks / 1 rank: {speed_up:.2f} x (loop), {one['wall'] / two['wall']:.2f} x (wall); "
            f"target >= {SPEED_UP_TARGET:g} (loop): {'met' if speed_up >= SPEED_UP_TARGET else 'NOT met'}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--skip-ensemble", action="store_true")
    parser.add_argument("--skip-ranks", action="store_true")
    parser.add_argument(
        "--before", default=BEFORE, metavar="REV", help=f"the revision to compare with (default {BEFORE})"
    )
    parser.add_argument("--quick", action="store_true", help="a tiny ensemble and a small hexagon (seconds)")
    args = parser.parse_args()
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-ensemble-"))
    try:
        if not args.skip_ranks:
            base, times_s = QUICK_SNAPSHOT_RUN if args.quick else SNAPSHOT_RUN
            bench_ranks(work, 1 if args.quick else args.repeats, base, times_s)
        if not args.skip_ensemble:
            bench_ensemble(work, 1 if args.quick else args.workers, QUICK_ENSEMBLE if args.quick else (), args.before)
    finally:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
