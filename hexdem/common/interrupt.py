"""A hexdem command stopped by SIGTERM or SIGINT: the run stops, cleans up and says so.

SIGTERM is what ``kill`` and batch schedulers send, SIGINT what Ctrl-C sends (to the terminal's
whole process group) or ``kill -INT`` (to hexdem alone). :func:`stop_on_signals` makes both
stop the command with :class:`Interrupted`, raised in the main thread, also where the process
was started with SIGINT ignored (a background job of a script), so that every ``finally`` on the
way out runs: a run's MPI launcher and ranks are stopped (:mod:`hexdem.experiments.parallel`),
an in-process LAMMPS run ends at its next sample (:mod:`hexdem.engines.lammps.driver`), a run's
staging folder and a study's half-run are removed (:func:`~hexdem.common.io.staged_directory`).
The command then ends with one line saying it was interrupted, with the shell's status for the
signal, 128 + its number (143 for SIGTERM, 130 for SIGINT).

**Raised only in hexdem's own code.** A signal can arrive between any two bytecodes: inside
importlib's bookkeeping of a module lock (a weakref callback, whose exception Python ignores,
leaving the lock held and the next import of that module waiting forever), inside a thread pool's
or a subprocess's bookkeeping, inside a library's ``finally``. The handler therefore raises only
where the code it interrupts is hexdem's own and no import is under way (:func:`may_raise_at`).
Elsewhere it remembers the signal and looks again every :data:`RETRY_S` seconds (SIGALRM),
and hexdem's waits poll :func:`raise_if_stopped`, so that the stop lands as soon as hexdem's code
runs. Blocks that must not be left half-done (LAMMPS's run, whose ctypes callbacks ignore an
exception raised on their entry; the publication of a run's files) hold the stop until they
end (:func:`deferred_signals`). The first stop is raised once; a later signal, while the first
is cleaned up after, is ignored, so that the clean-up finishes.

A run in another thread (a Parsl ThreadPoolExecutor's) installs no handler, which only the main
thread may, and stops all the same: the signals the process received are seen by every thread's
:func:`raise_if_stopped`, which LAMMPS's sampling callback and the publication of a run poll.
"""

from __future__ import annotations

import os
import signal
import threading
from contextlib import contextmanager

#: The signals that stop a hexdem command.
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT)
#: Seconds between two looks for a place to raise a stop that arrived outside hexdem's code.
RETRY_S = 0.02
#: Seconds between two looks for a stop in hexdem's waits (on a study's tasks, an MPI launcher).
WAIT_S = 0.1
#: Where hexdem's modules are (their code objects' file names start with it).
_PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep
#: The file names of importlib's frames (frozen, or from the standard library's sources).
_IMPORT_FILES = ("<frozen importlib.", os.path.dirname(os.__file__) + os.sep + "importlib" + os.sep)


class Interrupted(KeyboardInterrupt):
    """The process received ``signum``; a :class:`KeyboardInterrupt`, so that nothing that
    catches :class:`Exception` swallows it."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name

    @property
    def exit_status(self) -> int:
        """The shell's status for a process ended by the signal: 128 + its number."""
        return 128 + self.signum


#: The signals this process has received, first first.
_received: list[int] = []
#: Whether the main thread has raised the stop already (the next signals are ignored).
_stopping = False
#: Depth of the :func:`deferred_signals` blocks the main thread is in.
_deferring = 0
#: The code of the functions a stop is never raised in (:func:`shielded`).
_SHIELDED: set = set()


def remember(signum: int, frame=None) -> None:
    """Remember the signal ``signum`` for :func:`raise_if_stopped` (a signal handler)."""
    _received.append(signum)


def may_raise_at(frame) -> bool:
    """Whether an exception may be raised at ``frame``, the frame a signal interrupted: it is
    hexdem's own code, not a :func:`shielded` function's, and no frame below it is importing a
    module."""
    if frame is None or frame.f_code in _SHIELDED or not frame.f_code.co_filename.startswith(_PACKAGE):
        return False
    while frame is not None:
        if frame.f_code.co_filename.startswith(_IMPORT_FILES):
            return False
        frame = frame.f_back
    return True


def _on_stop_signal(signum, frame) -> None:
    if not _received:
        _received.append(signum)
    _raise_where_safe(frame)


def _on_retry(signum, frame) -> None:
    _raise_where_safe(frame)


def _raise_where_safe(frame) -> None:
    """Raise the first stop received at ``frame`` if it may (:func:`may_raise_at`); else look again
    in :data:`RETRY_S` seconds, unless a :func:`deferred_signals` block polls for it."""
    global _stopping
    if _stopping or _deferring or not _received:
        return
    if not may_raise_at(frame):
        signal.setitimer(signal.ITIMER_REAL, RETRY_S)
        return
    _stopping = True
    raise Interrupted(_received[0])


def stop_on_signals() -> None:
    """Make SIGTERM and SIGINT stop this process with :class:`Interrupted` (call it in the main
    thread)."""
    for signum in STOP_SIGNALS:
        signal.signal(signum, _on_stop_signal)
    signal.signal(signal.SIGALRM, _on_retry)
    signal.siginterrupt(signal.SIGALRM, False)  # a retry restarts the system call it interrupts


def shielded(function):
    """Decorate ``function`` so that a stop is never raised in its own code, only in the code it
    calls: for a command's outermost functions, which turn a stop into its one line and exit
    status, and would end in a traceback if the stop were raised outside their ``try``."""
    _SHIELDED.add(function.__code__)
    return function


def ignore_stops() -> None:
    """From now on, SIGTERM and SIGINT are ignored and a stop still to be raised is dropped: for a
    command whose work has ended, which exits with its own status."""
    signal.setitimer(signal.ITIMER_REAL, 0)
    for signum in STOP_SIGNALS:
        signal.signal(signum, signal.SIG_IGN)


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextmanager
def deferred_signals():
    """Within the block, SIGTERM and SIGINT are only remembered, and raised on leaving it: for a
    block that must not be left from any point (LAMMPS's run, whose ctypes callbacks ignore an
    exception raised on their entry and which polls :func:`raise_if_stopped` where it can stop;
    the moves that publish a run's files). In a thread other than the main one, where no signal
    handler runs, the block only ends with :func:`raise_if_stopped`."""
    global _deferring
    main = _in_main_thread()
    _deferring += main
    try:
        yield
    finally:
        _deferring -= main
    raise_if_stopped()


def stop_received() -> int | None:
    """The first of SIGTERM and SIGINT this process received, or None."""
    return _received[0] if _received else None


def raise_if_stopped() -> None:
    """Raise :class:`Interrupted` if this process has received SIGTERM or SIGINT (in any thread:
    a run in a worker thread stops with its process)."""
    global _stopping
    if _received:
        if _in_main_thread():
            _stopping = True
        raise Interrupted(_received[0])
