"""A run stopped by SIGTERM or SIGINT, or starved of disk, ends in one line of hexdem's and leaves
nothing in its --out (hexdem.common.interrupt)."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

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
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "hexdem",
            "run",
            "--config",
            str(tmp_path / "long.toml"),
            "--ranks",
            str(ranks),
            "--out",
            str(out),
        ],
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=ignore_sigint,
    )
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


@pytest.mark.parametrize(
    "ranks, signum, group",
    [(2, signal.SIGINT, True), (1, signal.SIGTERM, False)],
    ids=["Ctrl-C (the process group)", "SIGTERM, in-process"],
)
def test_a_stopped_run_ends_at_once_in_one_line_and_leaves_nothing(tmp_path, ranks, signum, group):
    status, err, seconds = start_and_stop(tmp_path, ranks, signum, group)
    assert status == 128 + signum
    assert err[-1] == LAST_LINE.format(signal.Signals(signum).name)
    assert seconds < 10
    time.sleep(1)  # no rank outlives the run and writes into --out after it
    assert not (tmp_path / "out").exists()


def catches_sigterm(pid: int) -> bool:
    """Whether the process ``pid`` has a handler of its own for SIGTERM (hexdem's, once installed)."""
    try:
        caught = next(
            line for line in Path(f"/proc/{pid}/status").read_text().splitlines() if line.startswith("SigCgt:")
        )
    except FileNotFoundError:
        return False
    return bool(int(caught.split()[1], 16) >> (signal.SIGTERM - 1) & 1)


#: The instants at which the sweep signals a 2-rank run of the 11-per-edge hexagon, as fractions of
#: the time from its handlers' start (its first import still ahead) to its end: its imports, its
#: deck, LAMMPS's start and run, the analysis, its figures and their publication.
INSTANTS = (0.0, 0.01, 0.03, 0.06, 0.1, 0.15, 0.25, 0.35, 0.5, 0.65, 0.8, 0.9, 0.97)
#: What a finished run leaves in its --out.
RESULT_FILES = [
    "arrival_map.png",
    "beads.csv",
    "deck",
    "energy_regions.csv",
    "front_shape.csv",
    "front_shape.png",
    "peak_decay.png",
    "peak_map.png",
    "peaks.csv",
    "summary.json",
]


def signal_at(tmp_path, instant, signum) -> tuple:
    """Start ``hexdem run`` (2 ranks) and send it ``signum`` ``instant`` seconds after its handlers
    are in place (None: once its results are published); return (exit status, stderr, seconds from
    the signal to its end, what its --out holds, seconds from its handlers' start to its end)."""
    tmp_path.mkdir()
    (tmp_path / "run.toml").write_text("ranks = 2\n")
    out = tmp_path / "out"
    process = subprocess.Popen(
        [sys.executable, "-m", "hexdem", "run", "--config", str(tmp_path / "run.toml"), "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 60
    while not catches_sigterm(process.pid):
        assert process.poll() is None and time.monotonic() < deadline, process.stderr.read()
        time.sleep(0.001)
    handled = time.monotonic()
    if instant is None:
        while not (out / "summary.json").exists() and time.monotonic() < deadline:
            time.sleep(0.001)
    else:
        time.sleep(instant)
    start = time.monotonic()
    process.send_signal(signum)
    _, err = process.communicate(timeout=30)
    end = time.monotonic()
    return process.returncode, err, end - start, sorted(path.name for path in out.glob("*")), end - handled


def test_a_run_signalled_at_any_instant_ends_in_one_line_or_finishes(tmp_path):
    """SIGTERM and SIGINT, in turn, at instants from before hexdem's first import to after its
    last file (the first signal once its results are published, which also times the run): the
    run ends within seconds with hexdem's one line, its status and nothing in --out, never a
    traceback or a hang; or, signalled once its results were published, it keeps them whole."""
    outcomes, duration = [], None
    for k, fraction in enumerate((None, *INSTANTS)):
        signum = (signal.SIGTERM, signal.SIGINT)[k % 2]
        instant = None if fraction is None else fraction * duration
        status, err, seconds, left, lasted = signal_at(tmp_path / str(k), instant, signum)
        duration = duration or lasted
        seen = f"signal {signum.name} at {instant} s: status {status}, {seconds:.1f} s, left {left}:\n{err}"
        assert "Traceback" not in err and "Exception ignored" not in err, seen
        assert seconds < 5, seen
        if left == RESULT_FILES:
            assert status in (0, 128 + signum), seen
        else:
            assert (status, left) == (128 + signum, []), seen
            assert err.strip().splitlines()[-1] == LAST_LINE.format(signum.name), seen
        outcomes.append(left == RESULT_FILES)
    assert outcomes[0] and not outcomes[1], "the instants did not span the run from its start to its results"
