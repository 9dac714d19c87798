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

from hexdem.common.interrupt import WAIT_S, raise_if_stopped

#: The loading threads started and not yet joined.
_LOADING: list[threading.Thread] = []
#: Guards :data:`_LOADING`, which the runs in several threads of one process share.
_LOADING_LOCK = threading.Lock()


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
    with _LOADING_LOCK:
        _LOADING.append(thread)
    thread.start()


def finish_background_loading() -> None:
    """Wait until every module asked of :func:`load_in_background` has loaded (or failed to): a
    process forked while another thread imports would hold that import's lock forever. A stop
    received meanwhile is raised (:mod:`hexdem.common.interrupt`)."""
    with _LOADING_LOCK:
        loading = list(_LOADING)
    for thread in loading:
        while thread.is_alive():
            thread.join(WAIT_S)
            raise_if_stopped()
    with _LOADING_LOCK:
        _LOADING[:] = [thread for thread in _LOADING if thread.is_alive()]
