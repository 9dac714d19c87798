"""Load modules in the background, while the process waits on something that leaves Python free.

An import holds the interpreter; LAMMPS's set-up (a foreign call, which releases it) and a
launched MPI job (a child process) do not. What a run will need later, the audit's pair search
or the figures of its results, loads then instead of on the run's critical path. A run's loop
calls back into Python at every sample, so it waits for the loading to finish first
(:func:`finish_background_loading`).
"""

from __future__ import annotations

import importlib
import threading

#: The loading threads started and not yet joined.
_LOADING: list[threading.Thread] = []


def load_in_background(*modules: str) -> None:
    """Import ``modules``, in order, in a daemon thread: their first use then finds them loaded
    (or waits for the import under way, as any import of a module being imported does). A module
    that fails to load is left for its first use, which imports it again and reports the error
    where it can be handled (a thread's exception would only print a traceback)."""

    def load():
        for module in modules:
            try:
                importlib.import_module(module)
            except Exception:
                return

    thread = threading.Thread(target=load, daemon=True)
    _LOADING.append(thread)
    thread.start()


def finish_background_loading() -> None:
    """Wait until every module asked of :func:`load_in_background` has loaded (or failed to): a
    process forked while another thread imports would hold that import's lock forever."""
    while _LOADING:
        _LOADING.pop().join()
