"""Progress of long work (LAMMPS runs, sweeps, ensembles) as a tqdm bar on stderr.

Bars appear only when stderr is a terminal (tqdm's ``disable=None``), so logs, pipes and
tests stay clean.
"""

from __future__ import annotations

import sys

from tqdm import tqdm


def progress_bar(total: int, description: str, unit: str = "it") -> tqdm:
    """A tqdm bar on stderr, shown only on a terminal."""
    return tqdm(total=total, desc=description, unit=unit, file=sys.stderr, disable=None,
                dynamic_ncols=True, leave=False)
