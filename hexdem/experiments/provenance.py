"""Where a result came from: the command, host, start time and the software that made it.

:func:`run_provenance` is taken when a run starts and written under ``summary.json``'s
``provenance`` key; :func:`versions` is also what ``hexdem --version`` prints. The git commit
is that of the checkout hexdem runs from (an editable install), or None for an installed copy.
"""

from __future__ import annotations

import platform
import socket
import subprocess
import sys
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from datetime import UTC, datetime
from functools import cache
from importlib.metadata import version
from pathlib import Path

from hexdem.engines.lammps.library import lammps_version, mpi_version


@cache
def source_commit() -> str | None:
    """The commit of the git checkout whose ``hexdem/`` is the package imported, with "-dirty"
    when tracked files differ from it; None when hexdem is not imported from a checkout (a copy
    installed inside some other repository, a virtual environment in the checkout included, is not
    the checkout's code)."""
    package = Path(__file__).resolve().parents[1]

    def git(*args) -> str | None:
        try:
            done = subprocess.run(["git", "-C", str(package), *args], capture_output=True, text=True, timeout=10)
        except (OSError, subprocess.TimeoutExpired):
            return None
        return done.stdout.strip() if done.returncode == 0 else None

    top = git("rev-parse", "--show-toplevel")
    if top is None or Path(top).resolve() / "hexdem" != package:
        return None
    commit = git("rev-parse", "HEAD")
    changes = git("status", "--porcelain", "--untracked-files=no")
    return None if commit is None else commit + ("-dirty" if changes else "")


@cache
def versions() -> dict[str, str | None]:
    """hexdem's version and commit, LAMMPS's and the MPI library's, and Python's."""
    return {
        "hexdem_version": version("hexdem"),
        "git_commit": source_commit(),
        "lammps_version": lammps_version(),
        "mpi_version": mpi_version(),
        "python_version": platform.python_version(),
    }


#: The command line hexdem is running in this process, as its user gave it (None: the process's own).
_command: list[str] | None = None


@contextmanager
def running_command(argv):
    """Within: ``argv`` is the command whose runs record it as their ``command`` (hexdem's CLI
    sets it, so that a command called from Python, a workflow's step or a test, records itself
    rather than the Python process's command line, which a study's workers are handed too)."""
    global _command
    previous, _command = _command, list(argv)
    try:
        yield
    finally:
        _command = previous


def user_command() -> list[str]:
    """The command line the user gave: hexdem's command being run (:func:`running_command`), else
    this process's."""
    return list(sys.argv if _command is None else _command)


def run_provenance(argv=None) -> dict:
    """The provenance of a run starting now: ``command`` (the argument vector, default
    :func:`user_command`), ``host``, ``start_time`` (ISO 8601, UTC) and :func:`versions`."""
    return started_provenance(argv)()


def started_provenance(argv=None) -> Callable[[], dict]:
    """:func:`run_provenance` of a run starting now, its :func:`versions` looked up in a thread
    while the run goes (three git commands and LAMMPS's and MPI's libraries, which would otherwise
    delay the start of every run from a checkout). Returns the function that gives it, once they
    are found."""
    started = {
        "command": user_command() if argv is None else list(argv),
        "host": socket.gethostname(),
        "start_time": datetime.now(UTC).isoformat(timespec="seconds"),
    }
    pool = ThreadPoolExecutor(1)
    found = pool.submit(versions)
    pool.shutdown(wait=False)  # its thread ends with the lookup
    return lambda: {**started, **found.result()}
