"""What every way of running a deck shares: its :class:`RunInfo`, LAMMPS's version and error
line from its log, and the bare run ``mpiexec -n N lmp -in in.hexdem`` of a deck by hand.

A deck names its files relative to its directory, so that it can be rerun by hand from there;
``lmp`` runs with the directory as its working directory, and LAMMPS inside hexdem's process is
handed their absolute paths instead (:func:`~hexdem.engines.lammps.driver.in_folder`): the
process's working directory never changes. Either way LAMMPS writes ``log.lammps`` there. A LAMMPS error becomes a
one-line
:class:`~hexdem.errors.RunFailed` with LAMMPS's own message and the deck path.
"""

from __future__ import annotations

import re
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

from hexdem.common.checks import positive_int
from hexdem.engines.lammps.deck import DECK_NAME, Deck
from hexdem.engines.lammps.library import environment_command
from hexdem.errors import RunFailed


@dataclass(frozen=True)
class RunInfo:
    """What a finished run reports: ``lammps_version`` (from the log), ``ranks``, ``wall_time_s``."""

    lammps_version: str
    ranks: int
    wall_time_s: float


def log_version(log: Path) -> str:
    """The LAMMPS version line a log starts with ("LAMMPS (22 Jul 2025 - Update 4)")."""
    first = log.read_text().splitlines()[0] if log.exists() else ""
    return first.strip() or "unknown"


def logged_step(log: Path) -> int:
    """The last step of the thermo output in the LAMMPS ``log`` (0 before any): how far a run on
    several ranks, in other processes, has gone (hexdem's decks flush their thermo lines)."""
    try:
        table = log.read_text().rsplit("Step", 1)[1]
    except (OSError, IndexError):
        return 0
    rows = [line.split() for line in table.splitlines()[1:]]
    steps = [int(row[0]) for row in rows if row and row[0].isdigit()]
    return steps[-1] if steps else 0


def error_line(text: str) -> str:
    """LAMMPS's ``ERROR...`` line from its output, without the source-file reference."""
    match = re.search(r"ERROR[^\n]*", text)
    line = match.group(0) if match else (text.strip().splitlines() or ["unknown error"])[-1]
    return re.sub(r"\s*\([^()]*\.cpp:\d+\)", "", line).strip()


def lammps_failure(directory: Path, output: str) -> RunFailed:
    """The one-line error of a failed run of the deck in ``directory``: LAMMPS's ERROR line from
    its log, or else from ``output`` (what the run printed or raised)."""
    log_path = Path(directory) / "log.lammps"
    log = log_path.read_text() if log_path.exists() else ""
    return RunFailed(f"LAMMPS failed on {Path(directory) / DECK_NAME}: {error_line(log if 'ERROR' in log else output)}")


def lmp_command(launcher: list[str], ranks: int, input_name: str = DECK_NAME) -> list[str]:
    """``launcher -n ranks lmp -in input_name`` (``launcher``: the MPI launcher's words; ``lmp``:
    this environment's), LAMMPS logging to ``log.lammps`` and printing nothing: a deck run as a
    user runs it by hand (:func:`run_bare`, and
    :func:`~hexdem.engines.lammps.standalone.run_deck` with a launcher)."""
    return [
        *launcher,
        "-n",
        str(ranks),
        environment_command("lmp"),
        "-in",
        input_name,
        "-log",
        "log.lammps",
        "-screen",
        "none",
        "-nocite",
    ]


def run_bare(deck: Deck, ranks: int = 1, input_name: str = DECK_NAME) -> RunInfo:
    """Run a deck as a user would by hand, ``mpiexec -n ranks lmp -in input_name`` (both from
    this environment), with no Python in the loop: the yardstick of hexdem's own runs."""
    ranks = positive_int("--ranks", ranks)
    command = lmp_command([environment_command("mpiexec")], ranks, input_name)
    start = time.perf_counter()
    done = subprocess.run(command, cwd=deck.directory, capture_output=True, text=True)
    if done.returncode != 0:
        raise lammps_failure(deck.directory, done.stderr + done.stdout)
    return RunInfo(log_version(deck.log_path), ranks, time.perf_counter() - start)
