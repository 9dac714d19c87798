"""``--launcher CMD`` on every command that starts MPI ranks: the job goes through the given
launcher (here one that wraps the local ``mpiexec``, as ``mpiexec -f hosts`` or ``srun`` would
span machines) and gives what the local launcher gives. ``hexdem paper --launcher`` is tested on
the session's quick paper (test_paper.py)."""

import json

import numpy as np
import pytest
from conftest import read_csv

from hexdem.cli.main import main
from hexdem.errors import HexdemError
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig

SMALL = "edge_beads = 5\n"


def small_config(folder) -> str:
    """A config file of the 5-per-edge experiment in ``folder``: its path."""
    path = folder / "small.toml"
    path.write_text(SMALL)
    return str(path)


def launched_since(log, count: int) -> list[str]:
    """The jobs the launcher started after the first ``count``."""
    return log.read_text().splitlines()[count:] if log.exists() else []


def jobs_so_far(log) -> int:
    return len(launched_since(log, 0))


def test_run_goes_through_the_launcher_with_the_same_peaks(launcher, tmp_path):
    command, log = launcher
    before = jobs_so_far(log)
    assert (
        main(
            [
                "run",
                "--config",
                small_config(tmp_path),
                "--ranks",
                "2",
                "--launcher",
                command,
                "--out",
                str(tmp_path / "out"),
            ]
        )
        == 0
    )
    (job,) = launched_since(log, before)
    assert job.startswith("-n 2 ") and "-P -m hexdem.experiments.parallel" in job
    local = simulate(RunConfig(edge_beads=5), tmp_path / "local").results
    _, rows = read_csv(tmp_path / "out" / "peaks.csv")
    peaks = np.array([float(row["peak_speed"]) for row in rows])
    expected = [local.peak_speed[bead] for name in ("0", "+30", "-30") for bead in local.lines[name]]
    np.testing.assert_allclose(peaks, expected, rtol=1e-9)


def test_one_rank_through_a_launcher_is_not_run_in_process(launcher, tmp_path):
    command, log = launcher
    before = jobs_so_far(log)
    analysis = simulate(RunConfig(edge_beads=3, launcher=command), tmp_path)
    assert launched_since(log, before)[0].startswith("-n 1 ") and analysis.engine["ranks"] == 1


def test_compare_and_snapshots_go_through_the_launcher(launcher, tmp_path):
    command, log = launcher
    before = jobs_so_far(log)
    assert (
        main(
            [
                "compare",
                "--config",
                small_config(tmp_path),
                "--ranks",
                "2",
                "--launcher",
                command,
                "--out",
                str(tmp_path / "compare"),
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "snapshots",
                "--edge-beads",
                "5",
                "--times",
                "0.1,0.2",
                "--ranks",
                "2",
                "--launcher",
                command,
                "--out",
                str(tmp_path / "snapshots"),
            ]
        )
        == 0
    )
    jobs = launched_since(log, before)
    assert [job.split()[:2] for job in jobs].count(["-n", "2"]) == 2
    assert json.loads((tmp_path / "snapshots" / "snapshots.json").read_text())["ranks"] == 2


def test_scaling_on_lammps_starts_each_run_through_the_launcher(launcher, tmp_path):
    """--workers runs at once in local processes; --launcher starts each run's rank."""
    command, log = launcher
    before = jobs_so_far(log)
    common = ["scaling", "--engine", "lammps", "--n-v0", "4", "--last", "5", "--workers", "2"]
    assert main([*common, "--launcher", command, "--out", str(tmp_path / "mpi")]) == 0
    assert [job.split()[:2] for job in launched_since(log, before)] == [["-n", "1"]] * 8
    assert main([*common, "--out", str(tmp_path / "local")]) == 0
    mpi, local = (json.loads((tmp_path / name / "scaling.json").read_text()) for name in ("mpi", "local"))
    for combination in ("30/30", "30/0", "0/0", "0/30"):
        for key in ("m", "b", "alpha", "beta"):
            assert mpi[combination][key] == pytest.approx(local[combination][key], rel=1e-12)


def test_an_empty_launcher_is_refused():
    with pytest.raises(HexdemError, match="launcher must be a command"):
        RunConfig(launcher="  ")


def test_a_launcher_that_does_not_exist_is_one_line(tmp_path, capfd):
    missing = str(tmp_path / "no-such-mpiexec")
    assert (
        main(
            [
                "run",
                "--config",
                small_config(tmp_path),
                "--ranks",
                "2",
                "--launcher",
                missing,
                "--out",
                str(tmp_path / "out"),
            ]
        )
        == 3
    )
    error = capfd.readouterr().err
    assert f"cannot start the MPI launcher '{missing}'" in error and "Traceback" not in error
    assert not (tmp_path / "out" / "summary.json").exists()


def test_a_launched_impacts_or_sweep_runs_process_loads_only_what_its_run_uses():
    """Every launched rank imports its task's module before it runs: an ensemble's impact
    (``hexdem.disorder.impacts``) and a V0-sweep run (``hexdem.theory.sweep``) load neither SciPy,
    matplotlib, tqdm (a progress bar) nor tomllib (a TOML file) there, only where a run uses them
    (the benchmarks page gives what they cost a rank)."""
    import subprocess
    import sys

    code = (
        "import sys; import hexdem.experiments.parallel, hexdem.disorder.impacts, hexdem.theory.sweep; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'scipy', 'matplotlib', 'tqdm', 'tomllib'}))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
