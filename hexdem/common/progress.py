"""Progress of long work (LAMMPS runs, sweeps, ensembles) as a tqdm bar on stderr.

Bars appear only when stderr is a terminal (tqdm's ``disable=None``), so logs, pipes and
tests stay clean. Work that shows one progress display of its own over many parts
(``hexdem paper``) silences the parts' bars with :func:`silenced`, also in the MPI ranks
and worker processes it starts (they inherit the environment).
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from tqdm import tqdm

#: Set (to "1") while bars are silenced; child processes inherit it.
SILENCE_VARIABLE = "HEXDEM_SILENCE_PROGRESS"


@contextmanager
def silenced():
    """No bars from :func:`progress_bar` inside this block, here or in processes it starts."""
    previous = os.environ.get(SILENCE_VARIABLE)
    os.environ[SILENCE_VARIABLE] = "1"
    try:
        yield
    finally:
        if previous is None:
            del os.environ[SILENCE_VARIABLE]
        else:
            os.environ[SILENCE_VARIABLE] = previous


def progress_bar(total: int, description: str, unit: str = "it") -> tqdm:
    """A tqdm bar on stderr, shown only on a terminal and outside :func:`silenced`. (tqdm is imported
    here, on a process's first bar: an MPI rank or a worker that shows none does not load it.)"""
    from tqdm import tqdm

    quiet = os.environ.get(SILENCE_VARIABLE) == "1"
    return tqdm(
        total=total,
        desc=description,
        unit=unit,
        file=sys.stderr,
        disable=True if quiet else None,
        dynamic_ncols=True,
        leave=False,
    )
