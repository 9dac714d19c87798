"""Many independent decks at once, on LAMMPS partitions (LAMMPS's multi-partition mode).

``mpiexec -n P lmp -partition Px1 -in run.in`` starts P independent one-rank LAMMPS
instances in one MPI job, on this machine or across as many as the MPI launcher reaches.
The driver ``run.in`` gives partition p (a ``world`` variable) the tasks p, p + P, p + 2P, …
in turn (``partition<p>.in``), so P partitions share N tasks with no scheduler of hexdem's own.
The tasks of one call cost about the same (the realizations of an ensemble), so the fixed
round-robin loses at most one task's time at the end. LAMMPS's own work queue, a ``uloop``
variable, is not used: its ``next`` sleeps a random fraction of a second before it takes its
lock file, about 0.5 s per deck (a third of a 331-bead settling). Task k ``shell cd``s into its deck
directory, logs to ``log.lammps`` there, includes ``in.hexdem``, ``clear``s (which closes
its dump and data files) and only then writes the marker ``hexdem.done``: a deck with the
marker is complete, one without it is never read.

The run can be repeated by hand: ``cd RUN_DIR && mpiexec -n P lmp -partition Px1 -in run.in``.
On Linux the launcher gets SIGTERM if hexdem dies, so that no orphaned LAMMPS keeps writing.
"""

from __future__ import annotations

import ctypes
import functools
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
from pathlib import Path

from hexdem.common.checks import positive_int
from hexdem.common.progress import progress_bar
from hexdem.engines.lammps.deck import DECK_NAME
from hexdem.engines.lammps.library import environment_command
from hexdem.engines.lammps.runner import RunInfo, error_line, log_version
from hexdem.errors import HexdemError

#: Written into a deck directory once its run has finished and closed its files.
DONE_MARKER = "hexdem.done"
DRIVER_NAME = "run.in"
POLL_S = 0.5


def is_done(directory) -> bool:
    return (Path(directory) / DONE_MARKER).exists()


def loop_time_s(log) -> float:
    """Sum of LAMMPS's "Loop time" over the runs of a log [s] (0 if none finished)."""
    text = Path(log).read_text() if Path(log).exists() else ""
    return sum(float(t) for t in re.findall(r"Loop time of ([0-9.eE+-]+)", text))


def lammps_version(run_dir) -> str:
    """The LAMMPS version line of a partitioned run in ``run_dir``."""
    return log_version(Path(run_dir) / "log.lammps.0")


def run_info(directory, version: str) -> RunInfo:
    """What a finished partitioned deck reports: one rank, its LAMMPS loop time."""
    return RunInfo(version, 1, loop_time_s(Path(directory) / "log.lammps"))


def _task(directory: Path, home: Path) -> str:
    return "\n".join([f'shell cd "{directory}"', "log log.lammps", f"include {DECK_NAME}", "clear",
                      f'print "complete" file {DONE_MARKER}', "log none", f'shell cd "{home}"', ""])


def write_driver(directories, run_dir: Path, partitions: int) -> Path:
    """Write ``run.in``, one ``partition<p>.in`` per partition and one ``task<k>.in`` per deck
    into ``run_dir``; returns the driver."""
    run_dir.mkdir(parents=True, exist_ok=True)
    for k, directory in enumerate(directories, 1):
        (run_dir / f"task{k}.in").write_text(_task(Path(directory).resolve(), run_dir.resolve()))
    for p in range(partitions):
        tasks = range(p + 1, len(directories) + 1, partitions)
        (run_dir / f"partition{p}.in").write_text("".join(f"include         task{k}.in\n" for k in tasks))
    driver = run_dir / DRIVER_NAME
    driver.write_text("\n".join([
        f"# hexdem: {len(directories)} decks on {partitions} LAMMPS partitions; partition p runs tasks p+1, p+1+{partitions}, ...",
        f"# run from this directory: mpiexec -n {partitions} lmp -partition {partitions}x1 -in {DRIVER_NAME}",
        f"variable        partition world {' '.join(map(str, range(partitions)))}",
        "include         partition${partition}.in", ""]))
    return driver


def die_with_parent(parent_pid: int) -> None:
    """In a child of process ``parent_pid``: get SIGTERM when it dies (Linux prctl;
    elsewhere nothing), or exit at once if it already has. For child processes that must not
    outlive hexdem and keep writing into its directories."""
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
        if os.getppid() != parent_pid:
            os._exit(1)


def _failure(directories, run_dir: Path, output: str) -> HexdemError:
    for directory in directories:
        log = Path(directory) / "log.lammps"
        if not is_done(directory) and log.exists() and "ERROR" in (text := log.read_text()):
            return HexdemError(f"LAMMPS failed on {Path(directory) / DECK_NAME}: {error_line(text)}")
    return HexdemError(f"LAMMPS partitions failed in {run_dir}: {error_line(output)}")


def launcher_command(launcher: str | None) -> list[str]:
    """The words of the MPI launcher command ``launcher`` (None: this environment's ``mpiexec``),
    refused in one line if its program is not an executable that can be found."""
    try:
        prefix = shlex.split(launcher) if launcher else [environment_command("mpiexec")]
    except ValueError as exc:
        raise HexdemError(f"launcher {launcher!r} is not a command: {exc}") from None
    if shutil.which(prefix[0]) is None:
        raise HexdemError(f"cannot start the MPI launcher {prefix[0]!r}: no such executable")
    return prefix


def run_partitioned(directories, workers: int, run_dir, description: str = "LAMMPS", launcher: str | None = None,
                    on_done=None, pass_fds=()) -> dict[Path, RunInfo]:
    """Run the decks in ``directories`` (each holding ``in.hexdem``) on ``workers`` partitions.

    ``launcher`` is the MPI launcher command (default: this environment's ``mpiexec``); hexdem
    appends ``-n P lmp -partition Px1 -in run.in``. ``on_done(directory)`` is called in this
    process as each deck completes. ``pass_fds`` are kept open in the launcher (e.g. a lock).
    Returns the :class:`RunInfo` of every deck.
    """
    directories = [Path(d) for d in directories]
    workers = positive_int("--workers", workers)
    if not directories:
        return {}
    prefix = launcher_command(launcher)
    run_dir = Path(run_dir)
    for directory in directories:
        (directory / DONE_MARKER).unlink(missing_ok=True)
    partitions = min(workers, len(directories))
    driver = write_driver(directories, run_dir, partitions)
    command = [*prefix, "-n", str(partitions), environment_command("lmp"), "-partition", f"{partitions}x1",
               "-in", driver.name, "-screen", "none", "-nocite"]
    output = run_dir / "launcher.out"
    pending, bar = list(directories), progress_bar(len(directories), f"{description} x{partitions}", unit="deck")
    with open(output, "w") as out:
        try:
            process = subprocess.Popen(command, cwd=run_dir, stdout=out, stderr=subprocess.STDOUT, pass_fds=pass_fds,
                                       preexec_fn=functools.partial(die_with_parent, os.getpid()))
        except OSError as exc:
            bar.close()
            raise HexdemError(f"cannot start the MPI launcher {prefix[0]!r}: {exc.strerror}") from None
    try:
        while pending:
            finished = process.poll() is not None
            for directory in [d for d in pending if is_done(d)]:
                pending.remove(directory)
                bar.update(1)
                if on_done is not None:
                    on_done(directory)
            if finished:
                break
            try:
                process.wait(timeout=POLL_S)  # returns as soon as the job ends
            except subprocess.TimeoutExpired:
                pass
        process.wait()
    finally:
        if process.poll() is None:
            process.terminate()
            process.wait()
        bar.close()
    if process.returncode != 0 or pending:
        raise _failure(pending, run_dir, output.read_text())
    version = lammps_version(run_dir)
    return {directory: run_info(directory, version) for directory in directories}
