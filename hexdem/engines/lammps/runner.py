"""Run a rendered deck: in-process through the ``lammps`` module, or with ``mpiexec -n N lmp``.

Either way LAMMPS runs inside the deck's directory (the deck uses relative paths, so that
it can be rerun by hand) and writes ``log.lammps`` there. A LAMMPS error becomes a
one-line :class:`~hexdem.errors.HexdemError` with LAMMPS's own message and the deck path.
"""

from __future__ import annotations

import os
import re
import subprocess
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from hexdem.common.checks import positive_int
from hexdem.common.progress import lammps_log_progress
from hexdem.engines.lammps.deck import DECK_NAME, Deck
from hexdem.engines.lammps.library import environment_command, load_lammps
from hexdem.errors import HexdemError


@dataclass(frozen=True)
class RunInfo:
    """What a finished run reports: ``lammps_version`` (from the log), ``ranks``, ``wall_time_s``."""

    lammps_version: str
    ranks: int
    wall_time_s: float


@contextmanager
def _working_directory(path: Path):
    previous = os.getcwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(previous)


def log_version(log: Path) -> str:
    """The LAMMPS version line a log starts with ("LAMMPS (22 Jul 2025 - Update 4)")."""
    first = log.read_text().splitlines()[0] if log.exists() else ""
    return first.strip() or "unknown"


def error_line(text: str) -> str:
    """LAMMPS's ``ERROR...`` line from its output, without the source-file reference."""
    match = re.search(r"ERROR[^\n]*", text)
    line = match.group(0) if match else (text.strip().splitlines() or ["unknown error"])[-1]
    return re.sub(r"\s*\([^()]*\.cpp:\d+\)", "", line).strip()


def _fail(deck: Deck, message: str) -> HexdemError:
    return HexdemError(f"LAMMPS failed on {deck.input_path}: {error_line(message)}")


def run_in_process(deck: Deck) -> RunInfo:
    """Run ``deck`` in this process on one rank."""
    lammps = load_lammps()
    start = time.perf_counter()
    with _working_directory(deck.directory):
        lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "log.lammps", "-nocite"])
        try:
            with lammps_log_progress(deck.log_path, deck.settings.n_steps):
                lmp.file(DECK_NAME)
        except Exception as exc:
            raise _fail(deck, str(exc)) from None
        finally:
            lmp.close()
    return RunInfo(log_version(deck.log_path), 1, time.perf_counter() - start)


def run_mpiexec(deck: Deck, ranks: int) -> RunInfo:
    """Run ``deck`` with ``mpiexec -n ranks lmp -in in.hexdem`` (both from this environment)."""
    command = [environment_command("mpiexec"), "-n", str(ranks), environment_command("lmp"),
               "-in", DECK_NAME, "-screen", "none", "-log", "log.lammps", "-nocite"]
    start = time.perf_counter()
    with lammps_log_progress(deck.log_path, deck.settings.n_steps, f"LAMMPS x{ranks}"):
        done = subprocess.run(command, cwd=deck.directory, capture_output=True, text=True)
    if done.returncode != 0:
        log = deck.log_path.read_text() if deck.log_path.exists() else ""
        raise _fail(deck, log if "ERROR" in log else done.stderr + done.stdout)
    return RunInfo(log_version(deck.log_path), ranks, time.perf_counter() - start)


def run_deck(deck: Deck, ranks: int = 1) -> RunInfo:
    """Run on ``ranks`` MPI ranks: in-process for one, through ``mpiexec`` for more."""
    ranks = positive_int("--ranks", ranks)
    return run_in_process(deck) if ranks == 1 else run_mpiexec(deck, ranks)
