"""``hexdem sweep``: a study of any run-config keys, every run a full ``hexdem run`` result.

:mod:`hexdem.experiments.sweep_plan` makes and checks the plan; this module plans it into the
study folder, runs it and collects it; :mod:`hexdem.experiments.sweep_table` tabulates and
draws it.

**Layout of DIR.** ``sweep.json`` (the plan: the base configuration, the varied keys and their
values), ``runs/<name>/`` (each run's full result directory, as ``hexdem run --out`` leaves it),
``runs/<name>.failed`` (the error of a run that failed, in one line), ``sweep.csv`` and
``sweep.png``. Every machine that runs a part of the study must see DIR at the same absolute
path (a shared filesystem).

**Running.** Each run is one task of a study executor (:mod:`hexdem.experiments.executors`):
``workers`` local processes, or Parsl with ``--parsl CONFIG.py``. A run takes ``ranks`` MPI
ranks of its own (``hexdem run --ranks``: ``mpiexec -n K``, or ``launcher``). A run that fails
is retried (once in the local pool, as Parsl's ``retries`` says with Parsl), then its error is
written to ``runs/<name>.failed`` and the study goes on (its deck kept in one folder of the
temporary directory per run, :func:`failed_deck_path`, which each try replaces); the table marks
it ``failed`` and the sweep ends with an error naming every run that failed. ``hexdem sweep DIR --run I`` runs run I
of a planned study alone, in this process, with no executor (one task of a Slurm job array),
and ``hexdem sweep DIR --collect`` writes the table and figure of whatever has finished.

**Resuming.** A run is done when its directory exists: it runs in ``runs/.<name>.part``, which
is removed if the run fails and renamed into place once all its files are written. A rerun of
the same command keeps the finished runs and runs the missing and failed ones again; the table
is read from the runs' files either way. A rerun with another plan is refused rather than mixed.
A study stopped by SIGTERM or SIGINT (:mod:`hexdem.common.interrupt`) stops its runs and keeps
the finished ones; no half-run is left.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import sys
import tempfile
from pathlib import Path

from hexdem.common.io import atomic_directory, ensure_writable_dir, keep_plan, locked_directory
from hexdem.errors import HexdemError, RunFailed, one_line
from hexdem.experiments.executors import check_study_options, holding, parsl_session, run_phase
from hexdem.experiments.provenance import user_command
from hexdem.experiments.sweep_plan import SweepRun, Variation, plan_sweep
from hexdem.model.unused_keys import on_engine

PLAN_NAME = "sweep.json"
RUNS_NAME = "runs"
FAILED_SUFFIX = ".failed"


def run_dir(out: Path, run: SweepRun) -> Path:
    return out / RUNS_NAME / run.name


def failure_path(out: Path, run: SweepRun) -> Path:
    return out / RUNS_NAME / f"{run.name}{FAILED_SUFFIX}"


def failed_deck_path(out: Path, run: SweepRun) -> Path:
    """Where a failed try of ``run`` keeps its deck, in this machine's temporary directory: one
    folder per run of the study, which each try replaces, so that the error names the folder of
    every try there was here."""
    from hexdem.experiments.run import FAILED_PREFIX

    study = hashlib.sha256(str(Path(out).resolve()).encode()).hexdigest()[:8]
    return Path(tempfile.gettempdir()) / f"{FAILED_PREFIX}{study}-{run.name}"


def run_status(out: Path, run: SweepRun) -> tuple[str, str]:
    """(status, error) of a run of the study in ``out``: done, failed (with its error) or missing."""
    if run_dir(out, run).is_dir():
        return "done", ""
    failed = failure_path(out, run)
    return ("failed", failed.read_text().strip()) if failed.exists() else ("missing", "")


def run_one(run: SweepRun, out: Path, ranks: int | None = None, launcher: str | None = None, command=None) -> None:
    """Run ``run`` (on ``ranks`` ranks started by ``launcher``, when given; a run on the reference
    engine on one, in one process) in its part directory and rename it into place when every file
    is written; a run that fails leaves no directory. ``command``: the study's argument vector, its
    runs' provenance (default: this process's)."""
    from hexdem.experiments.run import run_experiment

    chosen = run.config.replace(
        **{key: value for key, value in (("ranks", ranks), ("launcher", launcher)) if value is not None}
    )
    config = on_engine(chosen, chosen.engine)
    with atomic_directory(run_dir(out, run)) as partial:
        run_experiment(
            config, partial, log=lambda message: None, command=command, failed_deck=failed_deck_path(out, run)
        )


def plan_study(base: dict, variations: list[Variation], out, source: str = "the base configuration") -> list[SweepRun]:
    """Check the sweep and write its plan into ``out`` (a folder made if needed); its runs."""
    runs = plan_sweep(base, variations, source)
    out = ensure_writable_dir(out)
    keep_plan(out / PLAN_NAME, {"base": base, "vary": {v.key: list(v.texts) for v in variations}}, "sweep")
    ensure_writable_dir(out / RUNS_NAME)
    return runs


def planned_study(out) -> tuple[list[SweepRun], list[Variation]]:
    """The runs and variations of the study planned in ``out``."""
    path = Path(out) / PLAN_NAME
    try:
        plan = json.loads(path.read_text())
        base, vary = plan["base"], plan["vary"]
    except FileNotFoundError:
        raise HexdemError(
            f"{out} holds no planned sweep (no {PLAN_NAME}); plan it with "
            f"hexdem sweep --vary KEY=V1,V2,... --out {out} --plan-only"
        ) from None
    except (OSError, ValueError, KeyError, TypeError):
        raise HexdemError(f"{path} is unreadable: {out} does not hold a hexdem sweep") from None
    variations = [Variation.parse(f"{key}={','.join(texts)}") for key, texts in vary.items()]
    return plan_sweep(base, variations, str(path)), variations


def _record_failure(out: Path, run: SweepRun, error: BaseException) -> str:
    message = one_line(error)
    failure_path(out, run).write_text(message + "\n")
    return message


def run_study(
    out: Path,
    runs: list[SweepRun],
    workers: int = 1,
    parsl=None,
    ranks: int | None = None,
    launcher: str | None = None,
    log=None,
) -> None:
    """Run the runs of ``runs`` that are missing or failed in the study folder ``out``, each one a
    task of the study executor, recording the failures; ``parsl``: a Parsl configuration file, or
    its :class:`~hexdem.experiments.executors.ParslSession`."""
    log = log or _log
    parsl = parsl_session(parsl, out)
    with locked_directory(out, "another hexdem sweep"), holding(parsl, workers):
        for leftover in (out / RUNS_NAME).glob(".*.part"):
            shutil.rmtree(leftover, ignore_errors=True)
        todo = [run for run in runs if not run_dir(out, run).is_dir()]
        where = f"on Parsl ({parsl.path})" if parsl is not None else f"{min(workers, max(len(todo), 1))} at once"
        log(f"{len(runs)} runs ({len(runs) - len(todo)} done before), {where}")
        for run in todo:
            failure_path(out, run).unlink(missing_ok=True)
        named = {run.name: run for run in todo}
        tasks = {name: (run_one, run, out, ranks, launcher, user_command()) for name, run in named.items()}
        try:
            for name, error in run_phase(
                tasks, workers, parsl, "hexdem sweep", "run", done_before=len(runs) - len(todo)
            ):
                if error is not None:
                    log(f"run {name} failed: {_record_failure(out, named[name], error)}")
        except KeyboardInterrupt:  # stopped: the finished runs stay, a half-run its worker left goes
            for leftover in (out / RUNS_NAME).glob(".*.part"):
                shutil.rmtree(leftover, ignore_errors=True)
            raise


def run_single(
    out, runs: list[SweepRun], index: int, ranks: int | None = None, launcher: str | None = None
) -> tuple[SweepRun, bool]:
    """Run run ``index`` (from 0, in the plan's order) of ``runs``, the study planned in ``out``
    (:func:`planned_study`), in this process, unless it is done already (a job array's task that
    is requeued keeps the finished work, as ``hexdem sweep DIR`` does); (the run, whether it ran).
    A failure is recorded and raised as the run's failure."""
    check_study_options(ranks=ranks, launcher=launcher)
    out = Path(out)
    if not 0 <= index < len(runs):
        raise HexdemError(f"--run {index}: {out} plans runs 0 to {len(runs) - 1}")
    run = runs[index]
    if run_dir(out, run).is_dir():
        return run, False
    failure_path(out, run).unlink(missing_ok=True)
    try:
        run_one(run, out, ranks, launcher)
    except Exception as exc:
        raise RunFailed(f"run {index} ({run.name}) failed: {_record_failure(out, run, exc)}") from None
    return run, True


def collect(out: Path, runs: list[SweepRun], variations: list[Variation], log=None) -> list[tuple]:
    """Write the table and figure of the study in ``out``; its rows. The log ends by naming the
    runs that warned and why. Failed or missing runs are rows without figures, and then an error
    naming them once the table is written (a :class:`~hexdem.errors.RunFailed`: the study ran,
    and runs of it did not finish)."""
    from hexdem.experiments.run import RUN_WARNINGS
    from hexdem.experiments.sweep_table import sweep_figure, warned_runs, write_table

    log = log or _log
    states = [run_status(out, run) for run in runs]
    rows = write_table(out, runs, variations, states)
    sweep_figure(out, runs, variations, rows)
    log(f"results in {out / 'sweep.csv'}")
    warned = warned_runs(rows)
    if warned:
        count = len({cell for cells in warned.values() for cell in cells})
        reasons = "; ".join(
            f"{name} in {len(cells)} ({', '.join(Path(cell).name for cell in cells)}): {RUN_WARNINGS[name]}"
            for name, cells in warned.items()
        )
        log(f"{count} of {len(runs)} runs warned (the warnings column of sweep.csv): {reasons}")
    unfinished = {
        what: [run.name for run, (status, _) in zip(runs, states) if status == what] for what in ("failed", "missing")
    }
    if any(unfinished.values()):
        parts = [f"{len(names)} {what} ({'; '.join(names)})" for what, names in unfinished.items() if names]
        where = f"; errors in {out / RUNS_NAME}/NAME{FAILED_SUFFIX}" if unfinished["failed"] else ""
        raise RunFailed(
            f"{sum(map(len, unfinished.values()))} of {len(runs)} runs did not finish: "
            f"{', '.join(parts)}{where}; rerun to run them"
        )
    return rows


def _log(message: str) -> None:
    print(f"hexdem sweep: {message}", file=sys.stderr, flush=True)


def run_sweep(
    base: dict,
    variations: list[Variation],
    out,
    workers: int = 1,
    parsl=None,
    ranks: int | None = None,
    launcher: str | None = None,
    source: str = "the base configuration",
    log=None,
) -> list[tuple]:
    """Plan (or resume) the sweep into ``out``, run it and write its table and figure; the table's
    rows. An error names the runs that failed, after the table is written."""
    check_study_options(workers, launcher, ranks)
    parsl = parsl_session(parsl, out)
    runs = plan_study(base, variations, out, source)
    out = Path(out)
    run_study(out, runs, workers, parsl, ranks, launcher, log)
    return collect(out, runs, variations, log)
