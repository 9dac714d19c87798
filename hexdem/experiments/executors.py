"""Where the runs of a study go: a local process pool, or Parsl.

Every study (``hexdem sweep``, ``hexdem ensemble``'s impacts, ``hexdem scaling``'s V₀ sweep,
``hexdem paper``'s parts) hands each of its runs, one task each, to a
:class:`concurrent.futures.Executor` that :func:`study_executor` opens:

* by default a :class:`LocalPool` of ``workers`` spawned processes on this machine, one for
  all the studies that run while a command holds it (:func:`holding`), so that a command of
  many phases (``hexdem paper``: three for each of its ensembles) starts its workers once;
* with ``parsl`` (a :class:`ParslSession` of a Parsl configuration file that defines ``config``,
  a :class:`parsl.config.Config`) Parsl's DataFlowKernel of that configuration, behind
  :class:`ParslExecutor`, whose ``submit`` returns Parsl's AppFutures (they are
  :class:`concurrent.futures.Future` s). Parsl then places the tasks on whatever its providers
  reach (a Slurm allocation, a laptop) and retries them as its ``retries`` says. The file runs
  once a command and its DataFlowKernel serves all the command's studies (:func:`parsl_session`).

:func:`run_tasks` submits the tasks and yields each one's outcome as it finishes, so that a
failed task is recorded by the study and the others go on. A task whose local worker process
died or raised is submitted once more (:data:`LOCAL_RETRIES`); Parsl's tasks are retried by
Parsl. Tasks that write files must write them where every worker sees them at the same
absolute path (a shared filesystem across machines).
"""

from __future__ import annotations

import os
import runpy
import signal
import sys
from concurrent.futures import FIRST_COMPLETED, Executor, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from multiprocessing import get_context
from pathlib import Path

from hexdem.common.checks import positive_int
from hexdem.common.interrupt import STOP_SIGNALS, WAIT_S, Interrupted, raise_if_stopped, remember, stop_on_signals
from hexdem.common.progress import progress_bar
from hexdem.engines.lammps.standalone import die_with_parent, launcher_command
from hexdem.errors import HexdemError, RunFailed

#: Parsl's own default ``run_dir`` (relative to the current directory), where it writes its logs.
PARSL_RUN_DIR = "runinfo"
#: Times a task of the local pool is submitted again after it failed.
LOCAL_RETRIES = 1


class LocalPool(Executor):
    """A process pool of ``workers`` spawned processes that starts a fresh pool when one of its
    processes died (a broken :class:`ProcessPoolExecutor` takes no more tasks). The processes end
    with this one (on Linux), so that none keeps writing into a study that was killed, and stop
    as it does on SIGTERM and SIGINT (:mod:`hexdem.common.interrupt`), cleaning up their task."""

    def __init__(self, workers: int):
        self.workers = positive_int("--workers", workers)
        self._pool = self._new()

    def _new(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=get_context("spawn"),
            initializer=_start_worker,
            initargs=(os.getpid(),),
        )

    def submit(self, fn, /, *args, **kwargs):
        """A future of ``fn`` called with ``args`` and ``kwargs`` in a worker process (a fresh pool
        where a worker died)."""
        try:
            return self._pool.submit(_worker_task, fn, *args, **kwargs)
        except BrokenProcessPool:
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = self._new()
            return self._pool.submit(_worker_task, fn, *args, **kwargs)

    def shutdown(self, wait=True, *, cancel_futures=False):
        self._pool.shutdown(wait=wait, cancel_futures=cancel_futures)

    def stop(self) -> None:
        """Send SIGTERM to every worker process: each stops its task, which cleans up after itself."""
        for process in self._pool._processes.values():
            process.terminate()


#: The process whose :class:`LocalPool` this worker serves (set in the worker).
_study_pid: int | None = None


def _start_worker(parent_pid: int) -> None:
    """A worker of a :class:`LocalPool`: it ends with ``parent_pid``; SIGTERM or SIGINT while it
    holds no task is remembered (:func:`_worker_task`)."""
    global _study_pid
    _study_pid = parent_pid
    die_with_parent(parent_pid)
    _idle()


def _idle() -> None:
    """An idle worker remembers SIGTERM and SIGINT for its next task, unless the study is gone (the
    signal is die_with_parent's): then nothing will come, and it ends at once."""
    for signum in STOP_SIGNALS:
        signal.signal(signum, _idle_signal)


def _idle_signal(signum, frame) -> None:
    if os.getppid() != _study_pid:
        os._exit(128 + signum)
    remember(signum)


def _worker_task(fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` in a :class:`LocalPool` worker, which SIGTERM and SIGINT stop
    (:mod:`hexdem.common.interrupt`): the task cleans up after itself and raises
    :class:`~hexdem.common.interrupt.Interrupted`, and so does every task queued for the worker
    after it, without starting; the pool's shutdown then ends the worker."""
    raise_if_stopped()
    stop_on_signals()
    try:
        result = fn(*args, **kwargs)
    except Interrupted as stop:
        if os.getppid() != _study_pid:  # the study died (its SIGTERM came from die_with_parent): no one waits
            os._exit(stop.exit_status)
        raise
    finally:
        _idle()
    raise_if_stopped()
    return result


def _call(fn, *args, **kwargs):
    """The one Parsl app: any picklable callable, called on a worker. A task stopped with its
    process (:class:`~hexdem.common.interrupt.Interrupted`, in a thread of a Parsl
    ThreadPoolExecutor) fails as an ordinary exception: Parsl records only those, and would leave
    the study waiting for the task forever."""
    try:
        return fn(*args, **kwargs)
    except Interrupted as stop:
        raise RunFailed(f"stopped by {stop.name}") from None


def load_parsl_config(path):
    """The ``config`` that the Parsl configuration file ``path`` defines; a missing or broken
    file, one that exits, or one without a :class:`parsl.config.Config` named ``config``, is one
    clear line."""
    try:
        from parsl.config import Config
    except ImportError:
        raise HexdemError("--parsl needs Parsl: pip install 'hexdem[parsl]'") from None
    if not Path(path).is_file():
        raise HexdemError(f"--parsl {path}: no such file")
    try:
        namespace = runpy.run_path(str(path))
    except SystemExit as exc:  # sys.exit() in the file would end hexdem in silence, with its status
        raise HexdemError(
            f"--parsl {path}: the configuration file exits (sys.exit({exc.code!r})) instead of defining config"
        ) from None
    except Exception as exc:
        raise HexdemError(f"--parsl {path}: the configuration file fails: {type(exc).__name__}: {exc}") from None
    config = namespace.get("config")
    if not isinstance(config, Config):
        raise HexdemError(
            f"--parsl {path} must define config = parsl.config.Config(...), "
            f"got {type(config).__name__ if 'config' in namespace else 'no config'}"
        )
    return config


class ParslExecutor(Executor):
    """Parsl's DataFlowKernel of ``config`` as an :class:`Executor`: ``submit`` returns an
    AppFuture. Parsl retries failed tasks itself (``config.retries``)."""

    def __init__(self, config):
        from parsl import DataFlowKernel, python_app

        # Parsl's HighThroughputExecutor starts interchange.py and process_worker_pool.py from PATH
        os.environ["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
        self._dfk = DataFlowKernel(config)
        self._app = python_app(_call, data_flow_kernel=self._dfk)

    def submit(self, fn, /, *args, **kwargs):
        """A future of ``fn`` called with ``args`` and ``kwargs`` as a Parsl task."""
        return self._app(fn, *args, **kwargs)

    def shutdown(self, wait=True, *, cancel_futures=False):
        """Clean up Parsl's DataFlowKernel, after its tasks have finished if ``wait``."""
        if wait:
            self._dfk.wait_for_current_tasks()
        self._dfk.cleanup()


class ParslSession:
    """A Parsl configuration file (``path``) run once for a command, its ``config``, and the one
    :class:`ParslExecutor` of that configuration which all the command's studies share: Parsl
    starts a Config's executors only once, and a file may have effects of its own. The first study
    with tasks starts the executor; leaving the outermost ``with`` of the session cleans it up, so
    every study holds the session (:func:`holding`) while it runs, and a command whose studies
    share one (``hexdem paper``) holds it around them all."""

    def __init__(self, path, folder=None):
        self.path = path
        self.config = load_parsl_config(path)
        if folder is not None and self.config.run_dir == PARSL_RUN_DIR:
            self.config.run_dir = str(Path(folder).resolve() / PARSL_RUN_DIR)
        self._executor: ParslExecutor | None = None
        self._depth = 0

    def executor(self) -> ParslExecutor:
        """The command's Parsl executor, started at the first call."""
        if self._executor is None:
            self._executor = ParslExecutor(self.config)
        return self._executor

    def __enter__(self) -> ParslSession:
        self._depth += 1
        return self

    def __exit__(self, *exc_info) -> None:
        self._depth -= 1
        if self._depth == 0 and self._executor is not None:
            executor, self._executor = self._executor, None
            executor.shutdown()


def parsl_session(parsl, folder=None) -> ParslSession | None:
    """The :class:`ParslSession` of ``parsl``: None without Parsl, a session as it is, and a new
    one for a configuration file's path, whose file runs here, so that a bad file is refused in
    one line before anything is written. Parsl keeps its logs in the config's ``run_dir``; left at
    Parsl's default (``runinfo`` in the current directory), it goes into the study's ``folder``,
    ``folder/runinfo``."""
    if parsl is None or isinstance(parsl, ParslSession):
        return parsl
    return ParslSession(parsl, folder)


#: The :class:`LocalPool` that the studies share while a command holds it (:func:`holding`).
_held_pool: LocalPool | None = None


@contextmanager
def holding(parsl: ParslSession | None, workers: int = 1):
    """The context a study runs in: the session ``parsl`` held (see :class:`ParslSession`), or,
    without Parsl, a :class:`LocalPool` of ``workers`` processes that every study inside takes
    (:func:`study_executor`); held again inside, the outermost pool stays. Leaving the outermost
    ``with`` shuts the pool down; SIGTERM or SIGINT inside stops its workers first."""
    global _held_pool
    if parsl is not None:
        with parsl:
            yield
        return
    if _held_pool is not None:
        yield
        return
    with _local_pool(workers) as _held_pool:
        try:
            yield
        finally:
            _held_pool = None


@contextmanager
def _local_pool(workers: int):
    """A :class:`LocalPool` of ``workers`` processes, shut down on leaving; SIGTERM or SIGINT
    inside (:mod:`hexdem.common.interrupt`) stops its workers first, so that its runs stop too."""
    pool = LocalPool(workers)
    try:
        yield pool
    except KeyboardInterrupt:
        pool.stop()
        raise
    finally:
        pool.shutdown(cancel_futures=True)


def check_study_options(workers: int = 1, launcher: str | None = None, ranks: int | None = None) -> None:
    """Refuse a study's bad running options in one line, before anything is written: ``--workers``,
    a sweep's ``--ranks-per-run`` (``ranks``) and ``--launcher`` (``--parsl``: :func:`parsl_session`)."""
    positive_int("--workers", workers)
    if ranks is not None:
        positive_int("--ranks-per-run", ranks)
    if launcher is not None:
        launcher_command(launcher)


@contextmanager
def study_executor(workers: int, parsl: ParslSession | None = None):
    """The executor of a study's runs: the Parsl executor of the session ``parsl`` (shut down with
    the session), else the command's held :class:`LocalPool` (:func:`holding`), else a
    :class:`LocalPool` of ``workers`` processes, shut down on leaving."""
    if parsl is not None:
        yield parsl.executor()
        return
    if _held_pool is not None:
        yield _held_pool
        return
    with _local_pool(workers) as pool:
        yield pool


def tasks_failed(message: str, errors) -> HexdemError:
    """The error that ends a study whose tasks failed with ``errors``: a
    :class:`~hexdem.errors.RunFailed` (exit status 4: a LAMMPS error, a job whose ranks died, an
    energy check) unless every one of them refused its input (a plain
    :class:`~hexdem.errors.HexdemError`, exit status 3)."""
    refused = all(isinstance(error, HexdemError) and not isinstance(error, RunFailed) for error in errors)
    return (HexdemError if refused else RunFailed)(message)


def study_retries(parsl: ParslSession | None) -> int:
    """Times a failed task of the study executor (:func:`study_executor`) is submitted again:
    :data:`LOCAL_RETRIES` on the local pool, none on Parsl, which retries as its configuration's
    ``retries`` says."""
    return LOCAL_RETRIES if parsl is None else 0


def run_tasks(executor, tasks: dict, retries: int):
    """Submit ``tasks`` (``{key: (fn, *args)}``) to ``executor``; yield (key, result, error) as each
    finishes (``error``: None, or the exception of its last try), a failed task being submitted
    again up to ``retries`` times (:func:`study_retries`). The wait looks for a stop every
    :data:`~hexdem.common.interrupt.WAIT_S` seconds (:mod:`hexdem.common.interrupt`); tasks that
    finish within one look are yielded in the order they were submitted."""
    tries = dict.fromkeys(tasks, 0)
    futures = {executor.submit(*task): key for key, task in tasks.items()}
    while futures:
        done = wait(futures, timeout=WAIT_S, return_when=FIRST_COMPLETED).done
        raise_if_stopped()  # before a task that the stop ended is taken for a failure
        for future in [future for future in futures if future in done]:
            key = futures.pop(future)
            error = future.exception()
            if error is not None and tries[key] < retries:
                tries[key] += 1
                futures[executor.submit(*tasks[key])] = key
            else:
                yield key, None if error is not None else future.result(), error


def run_phase(tasks: dict, workers: int, parsl: ParslSession | None, label: str, unit: str, done_before: int = 0):
    """Run ``tasks`` (``{key: (fn, *args)}``: a sweep's runs, an ensemble's decks of one stage), one
    task of the study executor each (:func:`study_executor`), behind a progress bar ``label``
    counting ``unit`` s from ``done_before`` (those a previous command finished); yield (key, error)
    as each finishes (``error``: None, or the exception of its last try), so that the caller
    records a failure and the others go on. Without tasks nothing starts."""
    if not tasks:
        return
    bar = progress_bar(done_before + len(tasks), label, unit=unit)
    bar.update(done_before)
    with study_executor(min(workers, len(tasks)), parsl) as executor:
        for key, _, error in run_tasks(executor, tasks, study_retries(parsl)):
            yield key, error
            bar.update(1)
    bar.close()
