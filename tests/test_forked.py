"""Jobs shared with a forked child process (:mod:`hexdem.common.forked`): every job runs once, on
both sides where the machine has a core to spare, and an error on either side reaches the caller."""

import os
import signal
import subprocess
import sys

import pytest

import hexdem.common.forked as forked
from hexdem.errors import HexdemError, RunFailed


def writer(path, text="done"):
    return lambda: path.write_text(f"{text} {os.getpid()}")


def test_every_job_runs_once_and_every_other_one_in_a_child_where_a_core_is_spare(tmp_path):
    paths = [tmp_path / f"job{k}" for k in range(5)]
    forked.run_shared([writer(path) for path in paths])
    pids = [int(path.read_text().split()[1]) for path in paths]
    assert all(path.read_text().startswith("done") for path in paths)
    assert pids[0::2] == [os.getpid()] * 3
    if forked.spare_cores():
        assert len(set(pids[1::2])) == 1 and pids[1] != os.getpid()
    else:
        assert pids[1::2] == [os.getpid()] * 2


def test_without_a_spare_core_all_jobs_run_here_in_order(tmp_path, monkeypatch):
    monkeypatch.setattr(forked, "spare_cores", lambda: False)
    order = []
    forked.run_shared([lambda k=k: order.append((k, os.getpid())) for k in range(3)])
    assert order == [(0, os.getpid()), (1, os.getpid()), (2, os.getpid())]


@pytest.mark.skipif(not forked.spare_cores(), reason="one core: no child is forked")
def test_the_childs_error_is_raised_here_with_its_type_and_message(tmp_path):
    def fails():
        raise RunFailed("the child's figure could not be drawn")

    with pytest.raises(RunFailed, match="the child's figure could not be drawn"):
        forked.run_shared([writer(tmp_path / "first"), fails])
    assert (tmp_path / "first").exists()


@pytest.mark.skipif(not forked.spare_cores(), reason="one core: no child is forked")
def test_a_child_killed_by_a_signal_is_a_hexdem_error():
    with pytest.raises(HexdemError, match="ended with status -9"):
        forked.run_shared([lambda: None, lambda: os.kill(os.getpid(), signal.SIGKILL)])


@pytest.mark.skipif(not forked.spare_cores(), reason="one core: no child is forked")
def test_an_error_here_stops_the_child_and_is_raised(tmp_path):
    def fails():
        raise ValueError("this side failed")

    with pytest.raises(ValueError, match="this side failed"):
        forked.run_shared([fails, lambda: __import__("time").sleep(30)])


#: A command stopped (SIGTERM from another process, hexdem's handlers in place) while it waits for
#: the child, which still draws; it prints what the jobs' folder holds as the stop is raised and a
#: second later.
STOPPED_WHILE_THE_CHILD_DRAWS = """
import os, subprocess, sys, time
from pathlib import Path
from hexdem.common.forked import run_shared
from hexdem.common.interrupt import Interrupted, stop_on_signals

stop_on_signals()
out = Path(sys.argv[1])

def slow_figure():
    time.sleep(1)
    (out / "figure.png").write_text("drawn")

try:
    run_shared([lambda: subprocess.Popen(["sh", "-c", f"sleep 0.3; kill -TERM {os.getpid()}"]), slow_figure])
except Interrupted:
    print(sorted(path.name for path in out.iterdir()))
    time.sleep(1.5)
    print(sorted(path.name for path in out.iterdir()))
"""


@pytest.mark.skipif(not forked.spare_cores(), reason="one core: no child is forked")
def test_a_stop_while_the_child_draws_is_raised_once_the_child_has_ended(tmp_path):
    """A run's staging folder is removed as the stop is raised: a child still drawing into it then
    would leave it behind, so nothing may be written once run_shared has raised."""
    done = subprocess.run(
        [sys.executable, "-c", STOPPED_WHILE_THE_CHILD_DRAWS, str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert done.returncode == 0, done.stderr
    at_the_stop, a_second_later = done.stdout.splitlines()
    assert at_the_stop == a_second_later
