"""Decks run on their own, as a user runs them by hand (``cd DIR && lmp -in in.hexdem``), and
the MPI launcher that starts processes.

:func:`run_deck` is one task of a study (the ensembles' preparation stages hand each of their
decks to the study executor, :mod:`hexdem.experiments.executors`): LAMMPS logs to
``log.lammps`` in the deck's directory, and once it has closed its dump and data files the
marker ``hexdem.done`` is written: a deck with the marker is complete, one without it is
never read. On Linux the processes hexdem starts get SIGTERM if hexdem dies
(:func:`die_with_parent`), so that no orphaned LAMMPS keeps writing.
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

from hexdem.engines.lammps.library import environment_command
from hexdem.engines.lammps.runner import lammps_failure, lmp_command
from hexdem.engines.lammps.settling import run_settling_deck
from hexdem.errors import HexdemError

#: Written into a deck directory once its run has finished and closed its files.
DONE_MARKER = "hexdem.done"


def is_done(directory) -> bool:
    return (Path(directory) / DONE_MARKER).exists()


def loop_time_s(log) -> float:
    """Sum of LAMMPS's "Loop time" over the runs of a log [s] (0 if none finished)."""
    text = Path(log).read_text() if Path(log).exists() else ""
    return sum(float(t) for t in re.findall(r"Loop time of ([0-9.eE+-]+)", text))


def die_with_parent(parent_pid: int) -> None:
    """In a child of process ``parent_pid``: get SIGTERM when it dies (Linux prctl;
    elsewhere nothing), or exit at once if it already has. For child processes that must not
    outlive hexdem and keep writing into its directories."""
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
        if os.getppid() != parent_pid:
            os._exit(1)


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


def run_deck(directory, launcher: str | None = None) -> None:
    """Run ``in.hexdem`` in ``directory`` as ``lmp -in in.hexdem`` would: in this process, or in
    ``lmp`` on one rank that ``launcher`` starts; then write its done marker. A failure is one
    line naming the deck and LAMMPS's error."""
    directory = Path(directory)
    (directory / DONE_MARKER).unlink(missing_ok=True)
    if launcher is None:
        run_settling_deck(directory)
    else:
        command = lmp_command(launcher_command(launcher), 1)
        try:
            done = subprocess.run(
                command,
                cwd=directory,
                capture_output=True,
                text=True,
                preexec_fn=functools.partial(die_with_parent, os.getpid()),
            )
        except OSError as exc:
            raise HexdemError(f"cannot start the MPI launcher {command[0]!r}: {exc.strerror}") from None
        if done.returncode != 0:
            raise lammps_failure(directory, done.stdout + done.stderr)
    (directory / DONE_MARKER).write_text("complete\n")
