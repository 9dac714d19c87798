"""Ending a hexdem process without the interpreter's last garbage collections.

At its end the interpreter collects every object it still holds, cycles and all: with numba's and
scipy's many objects loaded, a noticeable time at each MPI rank's end and the ``hexdem`` command's,
which a run on N ranks waits for before its results are written (docs/validation/benchmarks.md,
*The analysis at the engine's speed*). A process that is about to end needs no memory back, so
the places where hexdem's processes end move what they hold out of the collector's reach first
(``gc.freeze``); the memory goes back to the system with the process.
"""

from __future__ import annotations

import gc


def skip_final_collections() -> None:
    """Keep the interpreter's collections at exit from going over what this process holds: call it
    only where the process ends."""
    gc.freeze()
