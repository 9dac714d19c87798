"""``hexdem sweep``: a study of any run-config keys, every run a full ``hexdem run`` result.

:mod:`hexdem.experiments.sweep_plan` makes and checks the plan; this module runs it and
:mod:`hexdem.experiments.sweep_table` tabulates and draws it.

**Running.** ``workers`` runs at once, each on a one-rank communicator of its own: a LAMMPS
instance, or the reference engine's process (:func:`~hexdem.experiments.parallel.spread_tasks`
inside :func:`~hexdem.experiments.parallel.run_on_ranks`, whose MPI ranks ``launcher`` may start
on other machines). A progress bar counts the runs done. A launcher whose program cannot be
found is refused before anything is written.

**Layout of DIR.** ``sweep.json`` (the plan: the base configuration, the varied keys and their
values), ``runs/<name>/`` (each run's full result directory, as ``hexdem run --out`` leaves it),
``sweep.csv`` and ``sweep.png``.

**Resuming.** A run is done when its directory exists: it runs in ``runs/.<name>.part`` and
is renamed into place once all its files are written. A rerun of the same command keeps the
finished runs, removes what an interrupted one left and runs it again; the table is read from
the runs' files either way. A rerun with another plan is refused rather than mixed.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from hexdem.common.checks import positive_int
from hexdem.common.io import ensure_writable_dir, locked_directory, write_json
from hexdem.engines.lammps.partitions import launcher_command
from hexdem.errors import HexdemError
from hexdem.experiments.parallel import run_on_ranks, spread_tasks
from hexdem.experiments.sweep_plan import SweepRun, Variation, plan_sweep

PLAN_NAME = "sweep.json"
RUNS_NAME = "runs"


@dataclass(frozen=True)
class SweepJob:
    """An MPI job: the ``runs`` into ``out / runs``, spread over the ranks."""

    runs: tuple[SweepRun, ...]
    out: Path

    def __call__(self, comm):
        spread_tasks(comm, self.runs, lambda run, alone: run_one(run, self.out, alone))


def run_dir(out: Path, run: SweepRun) -> Path:
    return out / RUNS_NAME / run.name


def run_one(run: SweepRun, out: Path, comm=None) -> None:
    """Run ``run`` in its part directory and rename it into place when every file is written."""
    from hexdem.experiments.run import run_experiment

    final = run_dir(out, run)
    partial = final.with_name(f".{final.name}.part")
    shutil.rmtree(partial, ignore_errors=True)
    try:
        run_experiment(run.config, partial, log=lambda message: None, comm=comm)
    except HexdemError as exc:
        raise HexdemError(f"run {run.name}: {exc}") from None
    os.replace(partial, final)


def _check_plan(out: Path, plan: dict) -> None:
    path = out / PLAN_NAME
    if path.exists():
        try:
            previous = json.loads(path.read_text())
        except (OSError, ValueError):
            raise HexdemError(f"{path} is unreadable: {out} does not hold a hexdem sweep; choose another --out") from None
        if previous != json.loads(json.dumps(plan)):
            raise HexdemError(f"{out} holds a sweep with another plan; rerun the same command to resume it, "
                              "or choose another --out")
    write_json(path, plan)


def run_sweep(base: dict, variations: list[Variation], out, workers: int = 1, launcher: str | None = None,
              source: str = "the base configuration", log=None) -> list[tuple]:
    """Run (or resume) the sweep into ``out`` and write its table and figure; the table's rows."""
    from hexdem.experiments.sweep_table import sweep_figure, write_table

    log = log or (lambda message: print(f"hexdem sweep: {message}", file=sys.stderr, flush=True))
    positive_int("--workers", workers)
    runs = plan_sweep(base, variations, source)
    if launcher is not None or workers > 1:
        launcher_command(launcher)  # refused before anything is written into out
    out = ensure_writable_dir(out)
    with locked_directory(out, "another hexdem sweep"):
        _check_plan(out, {"base": base, "vary": {v.key: list(v.texts) for v in variations}})
        ensure_writable_dir(out / RUNS_NAME)
        for leftover in (out / RUNS_NAME).glob(".*.part"):
            shutil.rmtree(leftover, ignore_errors=True)
        todo = tuple(run for run in runs if not run_dir(out, run).is_dir())
        log(f"{len(runs)} runs ({len(runs) - len(todo)} done before), {min(workers, max(len(todo), 1))} at once")
        if todo:
            done_before = len(runs) - len(todo)
            run_on_ranks(SweepJob(todo, out), min(workers, len(todo)), out / "mpi", launcher,
                         progress=(len(runs), "hexdem sweep", lambda: done_before + sum(
                             run_dir(out, run).is_dir() for run in todo)))
        rows = write_table(out, runs, variations)
        sweep_figure(out, runs, variations, rows)
    log(f"results in {out / 'sweep.csv'}")
    return rows
