"""Load modules in the background, while the process waits on something that leaves Python free.

An import holds the interpreter; LAMMPS's set-up and run (a foreign call, which releases it) and
a launched MPI job (a child process) do not. What a run will need later, the compiled kernels of
its samples (:mod:`hexdem.common.compiled`) or the figures of its results, loads then instead of
on the run's critical path.
"""

from __future__ import annotations

import importlib
import threading


def load_in_background(*modules: str) -> None:
    """Import ``modules``, in order, in a daemon thread: their first use then finds them loaded
    (or waits for the import under way, as any import of a module being imported does)."""

    def load():
        for module in modules:
            importlib.import_module(module)

    threading.Thread(target=load, daemon=True).start()
