"""Studies on an executor (hexdem.experiments.executors): a real Parsl HighThroughputExecutor on
this machine survives a worker killed mid-run and gives the serial sweep's runs; a failed run is
recorded and the others finish; runs of two ranks each; one run at a time of a planned study
(a job array's task) and the table collected after; bad input in one line; a --parsl file runs
once a command, an ensemble's phases sharing the one Parsl that the guide's file starts."""

import json
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil
import pytest
from conftest import read_csv

from hexdem.cli.main import main

#: A 6-per-edge hexagon (91 beads) for 3 ms: about half a second of LAMMPS a run.
SMALL = "edge_beads = 6\nduration = 3e-3\n"
#: The one-machine Parsl file that the guide ships.
SHIPPED_PARSL = Path(__file__).resolve().parents[1] / "docs" / "guide" / "parsl_local.py"
#: Six runs.
SIX = ["--vary", "v0=0.2,0.3,0.4", "--vary", "friction=0,0.1"]
#: Parsl on this machine: one block of two workers, a lost worker noticed within seconds, its
#: tasks retried on a block started afresh; the block started half a second after Parsl is (its
#: strategy's first look, 5 s after by default).
PARSL_CONFIG = """
from parsl.config import Config
from parsl.executors import HighThroughputExecutor
from parsl.providers import LocalProvider

config = Config(
    executors=[HighThroughputExecutor(label="local", address="127.0.0.1", max_workers_per_node=2,
                                      heartbeat_threshold=5, heartbeat_period=1, block_error_handler=False,
                                      provider=LocalProvider(init_blocks=1, min_blocks=1, max_blocks=1))],
    retries=2, strategy_period=0.5, run_dir="{run_dir}")
"""


def sweep(tmp_path, *options):
    base = tmp_path / "base.toml"
    base.write_text(SMALL)
    return main(["sweep", "--config", str(base), *options])


def parsl_config(tmp_path) -> str:
    path = tmp_path / "parsl_local.py"
    path.write_text(PARSL_CONFIG.format(run_dir=tmp_path / "runinfo"))
    return str(path)


def peaks_of(out) -> dict:
    _, rows = read_csv(out / "sweep.csv")
    return {row["run"]: read_csv(out / row["run"] / "peaks.csv") for row in rows}


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The six runs one after the other."""
    root = tmp_path_factory.mktemp("serial")
    assert sweep(root, *SIX, "--out", str(root / "out")) == 0
    return root / "out"


def kill_a_worker_mid_run(out, killed: list) -> None:
    """Once two runs are done, kill -9 the Parsl worker that has a part folder of this sweep's runs
    open (only this sweep's: the other tests' pools and Parsl workers, running beside it, live on)."""
    part_folders = f"{out / 'runs'}/."
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not killed:
        if len([path for path in (out / "runs").glob("*") if path.is_dir() and not path.name.startswith(".")]) >= 2:
            for process in psutil.process_iter(["cmdline"]):
                try:
                    if any("spawn_main" in word for word in process.info["cmdline"] or ()) and any(
                        f.path.startswith(part_folders) for f in process.open_files()
                    ):
                        process.kill()
                        killed.append(process.pid)
                        return
                except psutil.Error:
                    pass
        time.sleep(0.05)


def test_parsl_survives_a_killed_worker_with_the_serial_sweeps_runs(serial, tmp_path, capsys):
    out, killed = tmp_path / "out", []
    killer = threading.Thread(target=kill_a_worker_mid_run, args=(out, killed))
    killer.start()
    assert sweep(tmp_path, *SIX, "--out", str(out), "--parsl", parsl_config(tmp_path)) == 0
    killer.join()
    assert killed, "no worker was found mid-run"
    assert "6 runs (0 done before), on Parsl" in capsys.readouterr().err
    _, rows = read_csv(out / "sweep.csv")
    assert [row["status"] for row in rows] == ["done"] * 6
    assert peaks_of(out) == peaks_of(serial)
    assert not list((out / "runs").glob(".*"))
    for summary in (out / "runs").glob("*/summary.json"):  # the study's command, not the Parsl worker's
        assert json.loads(summary.read_text())["provenance"]["command"][:2] == ["hexdem", "sweep"], summary


def test_runs_of_two_ranks_each(serial, tmp_path, launcher):
    """--ranks-per-run 2: every run starts its own two ranks (here through a launcher that notes
    them) and gives the serial sweep's one-rank runs' peaks."""
    command, log = launcher
    before = len(log.read_text().splitlines()) if log.exists() else 0
    two = tmp_path / "two"
    assert (
        sweep(
            tmp_path,
            "--vary",
            "v0=0.2,0.4",
            "--vary",
            "friction=0",
            "--out",
            str(two),
            "--ranks-per-run",
            "2",
            "--launcher",
            command,
        )
        == 0
    )
    jobs = log.read_text().splitlines()[before:]
    assert sorted(job.split()[:2] for job in jobs) == [["-n", "2"]] * 2
    ours, one_rank = peaks_of(two), peaks_of(serial)
    assert sorted(ours) == ["runs/v0=0.2,friction=0", "runs/v0=0.4,friction=0"]
    for run, (_, mine) in ours.items():
        theirs = one_rank[run][1]
        speeds = [float(row["peak_speed"] or "nan") for row in mine]
        assert speeds == pytest.approx([float(row["peak_speed"] or "nan") for row in theirs], rel=1e-9, nan_ok=True), (
            run
        )


def test_a_job_arrays_runs_one_at_a_time_then_the_table(serial, tmp_path, capsys):
    """--plan-only lists the runs; --run I runs one (as a job array's task would), --collect
    names what is missing and then writes the serial sweep's table."""
    out = tmp_path / "out"
    assert sweep(tmp_path, "--vary", "v0=0.2,0.3", "--vary", "friction=0", "--out", str(out), "--plan-only") == 0
    listed = capsys.readouterr().out.splitlines()
    assert listed == ["0\tv0=0.2,friction=0", "1\tv0=0.3,friction=0"]
    assert main(["sweep", str(out), "--run", "1"]) == 0
    summary = out / "runs" / "v0=0.3,friction=0" / "summary.json"
    written = summary.stat().st_mtime_ns, summary.read_text()
    capsys.readouterr()
    assert main(["sweep", str(out), "--run", "1"]) == 0  # a requeued task keeps the finished run
    assert capsys.readouterr().out == "hexdem sweep: run 1 (v0=0.3,friction=0) was done already: kept\n"
    assert (summary.stat().st_mtime_ns, summary.read_text()) == written
    assert main(["sweep", str(out), "--collect"]) == 4
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert "1 missing (v0=0.2,friction=0)" in error and ".failed" not in error  # none failed: no file to point at
    assert main(["sweep", str(out), "--run", "0"]) == 0
    assert main(["sweep", str(out), "--collect"]) == 0
    ours = peaks_of(out)
    assert ours == {run: rows for run, rows in peaks_of(serial).items() if run in ours}


def test_a_failed_runs_tries_keep_one_deck_which_its_error_names(tmp_path, capsys, monkeypatch):
    """The local pool tries a failed run twice; the deck of its failure is kept in one folder of the
    temporary directory, which the recorded error names, not one folder a try."""
    import tempfile

    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setenv("TMPDIR", str(scratch))  # the pool's workers, spawned, read it
    monkeypatch.setattr(tempfile, "tempdir", None)
    out = tmp_path / "out"
    assert sweep(tmp_path, "--vary", "dt=3.5e-6", "--out", str(out), "--workers", "2") == 4
    assert "1 runs (0 done before), 1 at once" in capsys.readouterr().err  # no more workers than runs
    (kept,) = scratch.glob("hexdem-failed-*")
    assert f"{kept / 'deck'}" in (out / "runs" / "dt=3.5e-6.failed").read_text()
    assert (kept / "deck" / "in.hexdem").exists()


def test_a_job_arrays_failed_run_exits_as_a_failed_run(tmp_path, capsys):
    """--run I of a run whose energy check fails: recorded, and the status of a run that failed (4)."""
    out = tmp_path / "out"
    assert sweep(tmp_path, "--vary", "dt=3.5e-6", "--out", str(out), "--plan-only") == 0
    assert main(["sweep", str(out), "--run", "0"]) == 4
    assert "run 0 (dt=3.5e-6) failed: energy drift" in capsys.readouterr().err
    assert "energy drift" in (out / "runs" / "dt=3.5e-6.failed").read_text()


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["sweep", "{out}", "--run", "5"], "--run 5: {out} plans runs 0 to 1"),
        (["sweep", "{tmp}/nothing", "--collect"], "holds no planned sweep"),
        (["sweep", "{out}", "--vary", "v0=0.1"], "is a planned study"),
        (["sweep", "--vary", "v0=0.1,0.2"], "a sweep needs --vary"),
        (["sweep", "--run", "0"], "--run and --collect need the study folder"),
        (["sweep", "{out}", "--run", "0", "--parsl", "x.py"], "--run I runs here, without --parsl"),
        (["sweep", "{out}", "--run", "0", "--ranks-per-run", "0"], "--ranks-per-run must be a positive integer"),
        (["sweep", "{out}", "--workers", "0"], "--workers must be a positive integer"),
    ],
)
def test_bad_study_commands_are_one_line(tmp_path, capsys, arguments, message):
    out = tmp_path / "out"
    assert sweep(tmp_path, "--vary", "v0=0.2,0.3", "--out", str(out), "--plan-only") == 0
    capsys.readouterr()
    filled = [word.format(out=out, tmp=tmp_path) for word in arguments]
    assert main(filled) == 3  # a refused input
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and message.format(out=out) in lines[0], lines


@pytest.mark.parametrize(
    "text, message",
    [
        (None, "no such file"),
        ("config = 3\n", "must define config = parsl.config.Config(...), got int"),
        ("import nonexistent_module\n", "the configuration file fails: ModuleNotFoundError"),
        ("import sys\nsys.exit(0)\n", "the configuration file exits (sys.exit(0))"),
        ("import sys\nsys.exit(1)\n", "the configuration file exits (sys.exit(1))"),
    ],
)
def test_a_bad_parsl_file_is_one_line_before_anything_is_written(tmp_path, capsys, text, message):
    path = tmp_path / "parsl.py"
    if text is not None:
        path.write_text(text)
    assert sweep(tmp_path, "--vary", "v0=0.2,0.3", "--out", str(tmp_path / "out"), "--parsl", str(path)) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and f"--parsl {path}" in lines[0] and message in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_a_study_whose_tasks_failed_ends_as_they_did():
    """Tasks that ran and failed (a LAMMPS error, an MPI job whose ranks died, a bug) end the study
    as a run that failed, exit status 4; only tasks that all refused their input end it as refused, 3."""
    from hexdem.cli.main import exit_status
    from hexdem.errors import HexdemError, RunFailed
    from hexdem.experiments.executors import tasks_failed

    refused, failed, died = HexdemError("no"), RunFailed("LAMMPS failed"), RuntimeError("the MPI job on 2 ranks")
    assert [exit_status(tasks_failed("m", errors)) for errors in ([refused], [refused, failed], [died])] == [3, 4, 4]


@pytest.mark.parametrize("command", ["sweep", "ensemble", "scaling"])
def test_workers_and_parsl_together_are_a_usage_error(tmp_path, capsys, command):
    """--parsl places the runs itself: --workers beside it is refused as argparse refuses a usage
    error (status 2), not ignored."""
    with pytest.raises(SystemExit) as stopped:
        main([command, "--out", str(tmp_path / "out"), "--workers", "2", "--parsl", str(tmp_path / "parsl.py")])
    assert stopped.value.code == 2
    assert "--parsl: not allowed with argument --workers" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", ["ensemble", "scaling", "paper"])
def test_every_studys_bad_parsl_file_is_refused_before_anything_is_written(tmp_path, capsys, command):
    path, out = tmp_path / "parsl.py", tmp_path / "out"
    assert main([command, "--out", str(out), "--parsl", str(path)]) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and f"--parsl {path}: no such file" in lines[0], lines
    assert not out.exists()


def traced_parsl_config(tmp_path, text=None):
    """A Parsl configuration file (``text``; None: this file's local one) that also appends a line to
    ``loaded.log`` beside itself each time it runs; (its path, that log)."""
    path = Path(parsl_config(tmp_path))
    path.write_text(
        "from pathlib import Path\n"
        "with open(Path(__file__).with_name('loaded.log'), 'a') as log:\n    log.write('loaded\\n')\n"
        + (path.read_text() if text is None else text)
    )
    return str(path), tmp_path / "loaded.log"


def test_a_failed_run_is_recorded_and_the_others_finish(tmp_path, capsys):
    """dt = 3.5e-6 s passes the plan (under the contact time / 20) but its energy drift does not:
    retried as Parsl's config says, recorded, named at the end; a rerun runs only that one. A
    --parsl file is Python with whatever effects its author gave it: a sweep, planned or resumed,
    runs it once, its check and its runs together; a run's provenance is the study's command."""
    path, trace = traced_parsl_config(tmp_path)
    out = tmp_path / "out"
    assert sweep(tmp_path, "--vary", "dt=1e-7,3.5e-6", "--out", str(out), "--parsl", path) == 4  # a run failed
    assert trace.read_text() == "loaded\n"
    error = capsys.readouterr().err
    assert "run dt=3.5e-6 failed: energy drift" in error
    assert "1 of 2 runs did not finish: 1 failed (dt=3.5e-6)" in error.strip().splitlines()[-1]
    header, rows = read_csv(out / "sweep.csv")
    assert [(row["status"], row["error"][:12]) for row in rows] == [("done", ""), ("failed", "energy drift")]
    assert (out / "runs" / "dt=1e-7" / "peaks.csv").exists()
    assert not (out / "runs" / "dt=3.5e-6").exists() and not list((out / "runs").glob(".*"))
    assert "energy drift" in (out / "runs" / "dt=3.5e-6.failed").read_text()
    summary = json.loads((out / "runs" / "dt=1e-7" / "summary.json").read_text())
    assert summary["provenance"]["command"] == [
        "hexdem",
        "sweep",
        "--config",
        str(tmp_path / "base.toml"),
        "--vary",
        "dt=1e-7,3.5e-6",
        "--out",
        str(out),
        "--parsl",
        path,
    ]
    assert main(["sweep", str(out), "--parsl", path]) == 4
    assert trace.read_text() == "loaded\n" * 2
    assert "2 runs (1 done before), on Parsl" in capsys.readouterr().err
    _, rows = read_csv(out / "sweep.csv")
    assert [row["status"] for row in rows] == ["done", "failed"]


def test_an_ensemble_on_the_shipped_parsl_file_runs_it_once_with_its_logs_in_the_study(tmp_path, monkeypatch):
    """docs/guide/parsl_local.py, as a user copies it (here with a line that notes each time it
    runs): hexdem ensemble runs it once, its compaction, settling and impacts all on the one Parsl
    that it starts, and Parsl's runinfo/ goes into the ensemble's folder rather than the current
    directory."""
    monkeypatch.chdir(tmp_path)
    path, trace = traced_parsl_config(tmp_path, SHIPPED_PARSL.read_text())
    out = tmp_path / "ensemble"
    assert (
        main(
            [
                "ensemble",
                "--out",
                str(out),
                "--edge-beads",
                "4",
                "--velocities",
                "0.4",
                "--realizations",
                "1",
                "--parsl",
                path,
            ]
        )
        == 0
    )
    assert trace.read_text() == "loaded\n"
    assert (out / "peaks_stats.csv").exists()
    assert (out / "runinfo").is_dir() and not (tmp_path / "runinfo").exists()


def test_studies_inside_a_commands_parsl_session_share_its_parsl(tmp_path):
    """hexdem paper's way: each study holds the session its command holds around them all; one
    Parsl serves them, cleaned up when the command's hold ends."""
    from hexdem.experiments.executors import holding, parsl_session, study_executor

    path = tmp_path / "threads.py"
    path.write_text(
        "from parsl.config import Config\nfrom parsl.executors import ThreadPoolExecutor\n"
        "config = Config(executors=[ThreadPoolExecutor(max_threads=2)], "
        f"run_dir={str(tmp_path / 'runinfo')!r})\n"
    )
    session, used = parsl_session(str(path)), []
    with holding(session):
        for study in range(2):
            with holding(parsl_session(session)), study_executor(1, session) as executor:
                assert executor.submit(abs, -study).result() == study
                used.append(executor)
        assert not used[0]._dfk.cleanup_called
    assert used[0] is used[1] and used[0]._dfk.cleanup_called
    assert session._executor is None  # a closed session cannot hand out its cleaned-up Parsl again


def test_studies_inside_a_commands_hold_share_its_local_pools_workers():
    """Without Parsl, a command holds one local pool around its studies (hexdem paper: three phases
    for each ensemble): every phase's tasks go to the same worker processes, which end with the
    outermost hold, and a phase outside any hold starts a pool of its own."""
    import os

    from hexdem.experiments.executors import holding, study_executor

    with holding(None, 1):
        pids = []
        for _phase in range(3):
            with holding(None, 2), study_executor(1) as executor:
                pids.append(executor.submit(os.getpid).result())
        assert len(set(pids)) == 1 and pids[0] != os.getpid()
        worker = psutil.Process(pids[0])
    assert not worker.is_running() or worker.status() == psutil.STATUS_ZOMBIE
    with study_executor(1) as alone:
        assert alone.submit(os.getpid).result() != pids[0]


@pytest.mark.parametrize("wait, calls", [(True, ["wait_for_current_tasks", "cleanup"]), (False, ["cleanup"])])
def test_the_parsl_executors_shutdown_waits_for_its_tasks_only_when_asked(wait, calls):
    from hexdem.experiments.executors import ParslExecutor

    class Kernel:
        def __init__(self):
            self.calls = []

        def __getattr__(self, name):
            return lambda: self.calls.append(name)

    executor = object.__new__(ParslExecutor)  # its DataFlowKernel alone, without starting Parsl
    executor._dfk = Kernel()
    executor.shutdown(wait=wait)
    assert executor._dfk.calls == calls


@pytest.mark.parametrize("retries", [0, 2])
def test_a_failed_task_is_submitted_again_as_many_times_as_the_retries_given(retries):
    from concurrent.futures import ThreadPoolExecutor

    from hexdem.experiments.executors import run_tasks

    tries = []

    def fails(key):
        tries.append(key)
        raise ValueError(key)

    with ThreadPoolExecutor(1) as executor:
        ((key, result, error),) = run_tasks(executor, {"a": (fails, "a")}, retries)
    assert (key, result, type(error), len(tries)) == ("a", None, ValueError, 1 + retries)


def threads_config(tmp_path) -> Path:
    """Parsl's own default executor, a ThreadPoolExecutor of two threads."""
    threads = tmp_path / "threads.py"
    threads.write_text(
        "from parsl.config import Config\nfrom parsl.executors import ThreadPoolExecutor\n"
        "config = Config(executors=[ThreadPoolExecutor(label='threads', max_threads=2)], "
        f"run_dir={str(tmp_path / 'runinfo')!r})\n"
    )
    return threads


def test_two_runs_in_two_threads_of_one_process(serial, tmp_path):
    """``hexdem sweep --parsl`` on a Parsl ThreadPoolExecutor, as a user runs it, runs the sweep's
    runs in threads of its process: no run installs a signal handler (only the main thread may),
    with a relative --out each run keeps to its own folder (no run changes the process's working
    directory, which the threads share), and they give the runs of the serial sweep, whose runs
    were processes."""
    (tmp_path / "base.toml").write_text(SMALL)
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "hexdem",
            "sweep",
            "--config",
            "base.toml",
            "--vary",
            "v0=0.2,0.3",
            "--vary",
            "friction=0",
            "--out",
            "out",
            "--parsl",
            str(threads_config(tmp_path)),
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    _, rows = read_csv(tmp_path / "out" / "sweep.csv")
    assert [row["status"] for row in rows] == ["done", "done"] and not list((tmp_path / "out" / "runs").glob(".*"))
    ours = peaks_of(tmp_path / "out")
    assert len(ours) == 2 and ours == {run: rows for run, rows in peaks_of(serial).items() if run in ours}
    assert sorted(path.name for path in tmp_path.iterdir()) == ["base.toml", "out", "runinfo", "threads.py"]


def test_a_sweep_on_parsls_threads_stopped_mid_run_ends_in_one_line_and_keeps_no_half_run(tmp_path):
    """SIGTERM to ``hexdem sweep --parsl`` on Parsl's threads while two runs are in flight: the
    runs in the threads stop at their next sample (the process's stop, which their threads see),
    their part folders go, and the command ends as a stopped run does, within seconds."""
    (tmp_path / "base.toml").write_text("edge_beads = 25\nduration = 0.001\n")
    study = tmp_path / "study"
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "hexdem",
            "sweep",
            "--config",
            "base.toml",
            "--vary",
            "v0=0.2,0.3,0.4",
            "--out",
            str(study),
            "--parsl",
            str(threads_config(tmp_path)),
        ],
        cwd=tmp_path,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    while not list((study / "runs").glob(".*.part/.hexdem-run-*/deck/log.lammps")):
        assert process.poll() is None and time.monotonic() < deadline, process.stderr.read()
        time.sleep(0.05)
    start = time.monotonic()
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 143, err
    assert (
        err.strip().splitlines()[-1]
        == "hexdem: interrupted by SIGTERM: the run was stopped and nothing unfinished was kept"
    )
    assert time.monotonic() - start < 10
    assert not list((study / "runs").iterdir())


def test_the_local_pools_processes_end_with_a_killed_study(tmp_path):
    """A study killed outright leaves no worker behind to go on writing into its folder."""
    script = tmp_path / "killed.py"
    script.write_text(
        "import os, time\nfrom hexdem.experiments.executors import LocalPool\n"
        "if __name__ == '__main__':\n    pool = LocalPool(2)\n"
        "    print(*{pool.submit(os.getpid).result() for _ in range(4)}, flush=True)\n"
        "    pool.submit(time.sleep, 60)\n    os._exit(0)\n"
    )
    workers = [
        int(pid)
        for pid in subprocess.run(
            [sys.executable, str(script)], capture_output=True, text=True, check=True, timeout=60
        ).stdout.split()
    ]
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(psutil.pid_exists(pid) for pid in workers):
        time.sleep(0.1)
    assert workers and not any(psutil.pid_exists(pid) for pid in workers)


def test_the_guides_slurm_configuration_is_a_parsl_config(tmp_path):
    """The across-machines guide's Parsl configuration loads (its address made local)."""
    import re
    from pathlib import Path

    from parsl.providers import SlurmProvider

    from hexdem.experiments.executors import load_parsl_config

    guide = Path(__file__).resolve().parents[1] / "docs" / "guide" / "across-machines.md"
    (block,) = re.findall(r"```python\n(.*?)```", guide.read_text(), flags=re.DOTALL)
    path = tmp_path / "parsl_slurm.py"
    path.write_text(block.replace('address_by_interface("ib0")', '"127.0.0.1"'))
    config = load_parsl_config(path)
    assert config.retries == 2 and isinstance(config.executors[0].provider, SlurmProvider)
