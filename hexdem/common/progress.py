"""Progress of long work (LAMMPS runs, sweeps, ensembles) as a tqdm bar on stderr.

Bars appear only when stderr is a terminal (tqdm's ``disable=None``), so logs, pipes and
tests stay clean.
"""

from __future__ import annotations

import re
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

from tqdm import tqdm

#: A LAMMPS thermo line of hexdem decks: step, then numbers (``thermo_style custom step ...``).
_THERMO_LINE = re.compile(r"^[ \t]*(\d+)(?:[ \t]+[-+0-9.eE]+)+[ \t]*$", re.MULTILINE)


def progress_bar(total: int, description: str, unit: str = "it") -> tqdm:
    """A tqdm bar on stderr, shown only on a terminal."""
    return tqdm(total=total, desc=description, unit=unit, file=sys.stderr, disable=None,
                dynamic_ncols=True, leave=False)


@contextmanager
def lammps_log_progress(log: Path, n_steps: int, description: str = "LAMMPS", poll_s: float = 0.5):
    """Follow the thermo steps LAMMPS writes to ``log`` (flushed each output) while a run goes on."""
    bar = progress_bar(n_steps, description, unit="step")
    done = threading.Event()

    def follow():
        while not done.wait(poll_s):
            steps = _THERMO_LINE.findall(log.read_text()) if log.exists() else []
            if steps:
                bar.update(min(int(steps[-1]), n_steps) - bar.n)

    watcher = threading.Thread(target=follow, daemon=True)
    if not bar.disable:
        watcher.start()
    try:
        yield
    finally:
        done.set()
        if watcher.is_alive():
            watcher.join()
        bar.close()
