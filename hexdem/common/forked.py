"""Independent jobs shared with a forked child process, on a machine with a core to spare.

A run's result figures are drawn after the engine has finished, one after another, each from
a fraction of a second to a second, while the run's other cores sit idle
(docs/validation/benchmarks.md, *Figures behind choices in the code*). :func:`run_shared` hands
every other job to a child process forked from this one, which holds everything the jobs read
(the results, matplotlib and its fonts) without copying it, and runs the rest here.
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
import threading
from collections.abc import Callable, Sequence

from hexdem.common.interrupt import deferred_signals
from hexdem.common.preload import finish_background_loading
from hexdem.errors import HexdemError


def spare_cores() -> bool:
    """Whether this process may run on more than one core, the platform forks, and this is the
    main thread: a run in one thread of several (a Parsl ThreadPoolExecutor's) must not fork, as
    its child would inherit the locks the other threads hold at that moment, and wait on them forever."""
    return (
        hasattr(os, "fork")
        and hasattr(os, "sched_getaffinity")
        and len(os.sched_getaffinity(0)) > 1
        and threading.current_thread() is threading.main_thread()
    )


def run_shared(jobs: Sequence[Callable[[], None]]) -> None:
    """Run ``jobs`` (functions of no arguments, each writing its own files): the second, fourth, …
    in a child process forked from this one when :func:`spare_cores`, the others here; else all
    here, in order. An exception of either side is raised here once both have stopped, this side's
    first (the child's is sent back through a pipe; a child that dies of a signal is a
    :class:`~hexdem.errors.HexdemError`). The child is waited for however this side ends, a stop
    (:mod:`hexdem.common.interrupt`) included, which stops it first: no file of the jobs is written
    once this returns or raises."""
    if len(jobs) < 2 or not spare_cores():
        for job in jobs:
            job()
        return
    finish_background_loading()
    sys.stdout.flush()
    sys.stderr.flush()
    reader, writer = os.pipe()
    child = os.fork()
    if child == 0:
        os.close(reader)
        _run_child(jobs[1::2], writer)
    os.close(writer)
    try:
        with os.fdopen(reader, "rb") as pipe:
            for job in jobs[0::2]:
                job()
            report = pipe.read()
    except BaseException:  # an error here, or a stop while the child draws: it is stopped too
        os.kill(child, signal.SIGTERM)
        raise
    finally:
        with deferred_signals():  # the child has ended, and written its last file, before anything goes on
            _, status = os.waitpid(child, 0)
    if report:
        raise pickle.loads(report)
    if status != 0:
        raise HexdemError(f"a process drawing results ended with status {os.waitstatus_to_exitcode(status)}")


def _run_child(jobs, writer: int) -> None:
    """The child's side of :func:`run_shared`: its jobs, then an exit that runs nothing of the
    parent's (no exit handlers, no buffers flushed twice); an exception goes to ``writer`` pickled."""
    status = 0
    try:
        for job in jobs:
            job()
    except BaseException as exc:  # the parent raises it
        status = 1
        try:
            report = pickle.dumps(exc)
        except Exception:
            report = pickle.dumps(HexdemError(f"{type(exc).__name__}: {exc}"))
        with os.fdopen(writer, "wb") as pipe:
            pipe.write(report)
    finally:
        os._exit(status)
