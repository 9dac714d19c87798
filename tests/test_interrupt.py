"""A run stopped by SIGTERM or SIGINT, or starved of disk, ends in one line of hexdem's and leaves
nothing in its --out (hexdem.common.interrupt)."""

import errno
import os
import signal
import subprocess
import sys
import time

import pytest

from hexdem.cli.main import main

#: 3,571 beads for 1 ms: still running several seconds after LAMMPS has started.
LONG_RUN = "edge_beads = 35\nduration = 0.001\n"
LAST_LINE = "hexdem: interrupted by {}: the run was stopped and nothing unfinished was kept"


def ignore_sigint():
    """As a script's background job starts: SIGINT ignored, which hexdem must not inherit."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def start_and_stop(tmp_path, ranks: int, signum: int, group: bool):
    """Start ``hexdem run`` on LONG_RUN, send ``signum`` to it (``group``: to its process group, as
    Ctrl-C does) once LAMMPS has started, and return (exit status, stderr lines, seconds to end)."""
    (tmp_path / "long.toml").write_text(LONG_RUN)
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "hexdem", "run", "--config", str(tmp_path / "long.toml"),
                                "--ranks", str(ranks), "--out", str(out)], stderr=subprocess.PIPE, text=True,
                               start_new_session=True, preexec_fn=ignore_sigint)
    deadline = time.monotonic() + 120
    while not list(out.glob(".hexdem-run-*/deck/log.lammps")):
        assert process.poll() is None and time.monotonic() < deadline, process.stderr.read()
        time.sleep(0.05)
    time.sleep(0.5)
    assert process.poll() is None, "the run ended before it could be stopped: make LONG_RUN longer"
    start = time.monotonic()
    if group:
        os.killpg(process.pid, signum)
    else:
        process.send_signal(signum)
    _, err = process.communicate(timeout=60)
    return process.returncode, err.strip().splitlines(), time.monotonic() - start


@pytest.mark.parametrize("ranks, signum, group", [
    (2, signal.SIGTERM, False), (2, signal.SIGINT, False), (2, signal.SIGINT, True), (1, signal.SIGTERM, False)],
    ids=["SIGTERM, 2 ranks", "SIGINT to hexdem alone", "Ctrl-C (the process group)", "SIGTERM, in-process"])
def test_a_stopped_run_ends_at_once_in_one_line_and_leaves_nothing(tmp_path, ranks, signum, group):
    status, err, seconds = start_and_stop(tmp_path, ranks, signum, group)
    assert status == 128 + signum
    assert err[-1] == LAST_LINE.format(signal.Signals(signum).name)
    assert seconds < 10
    time.sleep(1)  # no rank outlives the run and writes into --out after it
    assert not (tmp_path / "out").exists()


def test_a_full_disk_is_one_line_naming_the_folder_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    """A figure that cannot be written for want of space (PIL's ``No space left on device``) ends the
    run in one line naming --out, exit 3; the files written before it are removed with the rest."""
    from matplotlib.figure import Figure

    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(Figure, "savefig", full)
    (tmp_path / "small.toml").write_text("edge_beads = 4\n")
    out = tmp_path / "out"
    status = main(["run", "--config", str(tmp_path / "small.toml"), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 3
    assert err[-1] == (f"hexdem: error: no space left on the device of {out} while writing the run's files; "
                       "nothing was kept: free some space or choose another --out")
    assert not any("Traceback" in line for line in err)
    assert not out.exists()


def test_a_full_filesystem_is_one_line_and_leaves_nothing(tmp_path):
    """The same on a real 300 kB filesystem (a tmpfs; root only): the run's figures do not fit."""
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", str(disk)], capture_output=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a 300 kB tmpfs here: {mounted.stderr.decode().strip() or 'mount failed'}")
    try:
        (tmp_path / "run.toml").write_text("edge_beads = 11\n")
        done = subprocess.run([sys.executable, "-m", "hexdem", "run", "--config", str(tmp_path / "run.toml"),
                               "--out", str(disk / "out")], capture_output=True, text=True)
        assert done.returncode == 3, done.stderr
        assert done.stderr.strip().splitlines()[-1].startswith(f"hexdem: error: no space left on the device of {disk / 'out'}")
        assert not any(disk.iterdir())
    finally:
        subprocess.run(["umount", str(disk)], check=True)


def test_a_stopped_sweep_keeps_its_finished_runs_and_no_half_run(tmp_path):
    """SIGTERM while a study's second run is running: the first stays, the second's part folder goes,
    and the command ends as a stopped run does."""
    (tmp_path / "base.toml").write_text("edge_beads = 25\nduration = 0.001\n")
    study, runs = tmp_path / "study", tmp_path / "study" / "runs"
    process = subprocess.Popen([sys.executable, "-m", "hexdem", "sweep", "--config", str(tmp_path / "base.toml"),
                                "--vary", "v0=0.2,0.3,0.4", "--workers", "1", "--out", str(study)],
                               stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 180
    while not ((runs / "v0=0.2").is_dir() and list(runs.glob(".v0=0.3.part/.hexdem-run-*/deck/log.lammps"))):
        assert process.poll() is None and time.monotonic() < deadline, process.stderr.read()
        time.sleep(0.05)
    start = time.monotonic()
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 143
    assert err.strip().splitlines()[-1] == LAST_LINE.format("SIGTERM")
    assert time.monotonic() - start < 10
    time.sleep(1)
    assert sorted(path.name for path in runs.iterdir()) == ["v0=0.2"]
