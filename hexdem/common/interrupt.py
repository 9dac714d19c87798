"""A hexdem command stopped by SIGTERM or SIGINT: the run stops, cleans up and says so.

SIGTERM is what ``kill`` and batch schedulers send, SIGINT what Ctrl-C sends (to the terminal's
whole process group) or ``kill -INT`` (to hexdem alone). :func:`stop_on_signals` makes both
raise :class:`Interrupted` in the main thread, also where the process was started with SIGINT
ignored (a background job of a script), so that every ``finally`` on the way out runs: a run's
MPI launcher and ranks are stopped (:mod:`hexdem.experiments.parallel`), an in-process LAMMPS
run ends at its next sample (:mod:`hexdem.engines.lammps.driver`), a run's staging folder and a
study's half-run are removed (:func:`~hexdem.common.io.staged_directory`). The command then ends
with one line saying it was interrupted, with the shell's status for the signal, 128 + its
number (143 for SIGTERM, 130 for SIGINT). A second signal while the first is being cleaned up
is ignored, so that the clean-up finishes. The signal is also remembered: an exception raised
where nothing can catch it (a ctypes callback, which ignores it) is raised again by the next
:func:`raise_if_stopped`, so that a stopped run is never published.
"""

from __future__ import annotations

import signal
from contextlib import contextmanager

#: The signals that stop a hexdem command.
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT)


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


def remember(signum: int, frame=None) -> None:
    """Remember the signal ``signum`` for :func:`raise_if_stopped` (a signal handler)."""
    _received.append(signum)


def _raise(signum, frame) -> None:
    _received.append(signum)
    for other in STOP_SIGNALS:  # the first signal is cleaned up after; the next ones wait for it
        signal.signal(other, signal.SIG_IGN)
    raise Interrupted(signum)


def stop_on_signals() -> None:
    """Make SIGTERM and SIGINT raise :class:`Interrupted` in the main thread (call it there)."""
    for signum in STOP_SIGNALS:
        signal.signal(signum, _raise)


@contextmanager
def deferred_signals():
    """Within the block, SIGTERM and SIGINT that would raise :class:`Interrupted` are only
    remembered, and raised on leaving it: for a block that Python cannot leave cleanly from any
    point (LAMMPS's run, whose ctypes callbacks ignore an exception raised on their entry), which
    polls :func:`raise_if_stopped` where it can stop."""
    ours = [signum for signum in STOP_SIGNALS if signal.getsignal(signum) is _raise]
    for signum in ours:
        signal.signal(signum, remember)
    try:
        yield
    finally:
        for signum in ours:
            signal.signal(signum, signal.SIG_IGN if _received else _raise)
    raise_if_stopped()


def raise_if_stopped() -> None:
    """Raise :class:`Interrupted` if this process has received SIGTERM or SIGINT."""
    if _received:
        raise Interrupted(_received[0])
