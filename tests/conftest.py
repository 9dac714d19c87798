"""Shared fixtures and helpers: one real LAMMPS run of the paper's default experiment per
session, tiny packings for two-body collisions, and a weakly disordered model."""

import csv
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from hexdem.analysis.peaks import refine_peak
from hexdem.analysis.trajectory import TrajectoryRecorder
from hexdem.experiments.run import run_experiment, simulate
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel, Impact
from hexdem.model.materials import DELRIN, STEEL_316
from hexdem.model.model_builder import build_model
from hexdem.model.packing import Packing
from hexdem.model.run_settings import contact_time_s, run_settings
from hexdem.model.triangular import hexagon

D, V0 = 0.01905, 0.4

# The suite's processes keep the bytecode they compile, as Python does by default: in an environment
# that turns that off (PYTHONDONTWRITEBYTECODE), each of the hundreds of processes the suite starts
# (CLI runs, MPI ranks, pool workers) would compile hexdem's modules again.
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
sys.dont_write_bytecode = False

#: The controller's compilation of the reference engine's kernels (:func:`pytest_sessionstart`).
WARM_UP = pytest.StashKey[subprocess.Popen]()


def compile_reference_kernels() -> None:
    """A short run of the reference engine without friction and one with: numba compiles both
    kernels into its cache, with the argument types that every reference run passes."""
    with tempfile.TemporaryDirectory() as folder:
        for friction in (0.0, 0.3):
            simulate(
                RunConfig(edge_beads=2, engine="reference", friction=friction, duration=1e-4),
                Path(folder) / str(friction),
            )


def pytest_sessionstart(session):
    """Under pytest-xdist the controller, which runs no test, compiles the reference engine's kernels
    (:func:`compile_reference_kernels`, in a process of its own) while the workers start: in a fresh
    clone two workers whose first reference runs meet would otherwise each compile the same kernels,
    seconds of CPU apiece. A run that comes before the cache is written compiles for itself, as
    without this."""
    config = session.config
    if not hasattr(config, "workerinput") and config.getoption("numprocesses", None):
        config.stash[WARM_UP] = subprocess.Popen(
            [sys.executable, "-c", "import conftest; conftest.compile_reference_kernels()"],
            cwd=Path(__file__).parent,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )


def pytest_sessionfinish(session):
    warm_up = session.config.stash.get(WARM_UP, None)
    if warm_up is not None:
        warm_up.wait()


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist's own, which reads the groups
def pytest_collection_modifyitems(items):
    """Every test that needs the session's ``hexdem paper --quick`` (a minute or more) is ``slow``. Under
    ``pytest -n N --dist loadgroup`` (pytest-xdist, as CI runs the suite) those tests share one
    worker, which runs the paper once (a test that asks for the paper as it runs carries the
    ``paper_quick`` group itself); the tests that read the default experiment's session runs
    (``default_run``, ``dumped_run``) share one worker, which runs each once; the tests of a file
    that share a module's fixture (a docs build, a wheel's install) share one worker, which builds
    it once; every other test goes to whichever worker is free. The longest work goes out first
    (the slow tests, then the groups, each a worker's for as long as it lasts), so that no worker
    waits at the end behind a long one."""
    for item in items:
        names = getattr(item, "fixturenames", ())
        if "paper_quick" in names:
            item.add_marker(pytest.mark.slow)
            item.add_marker(pytest.mark.xdist_group("paper_quick"))
        elif "default_run" in names or "dumped_run" in names:
            item.add_marker(pytest.mark.xdist_group("default_experiment"))
        elif item.get_closest_marker("xdist_group") is None and shares_a_module_fixture(item):
            item.add_marker(pytest.mark.xdist_group(item.path.stem))
    items.sort(
        key=lambda item: (item.get_closest_marker("slow") is None, item.get_closest_marker("xdist_group") is None)
    )


def shares_a_module_fixture(item) -> bool:
    """Whether ``item`` uses a fixture that its file's other tests share: one built once per module
    or class, or one of the session that the file defines itself."""
    info = getattr(item, "_fixtureinfo", None)
    own = item.nodeid.split("::")[0]
    return info is not None and any(
        definition.scope in ("module", "class") or (definition.scope == "session" and definition.baseid == own)
        for definitions in info.name2fixturedefs.values()
        for definition in definitions
    )


@pytest.fixture(scope="session")
def default_run(tmp_path_factory):
    """``hexdem run`` with no options (11 per edge, steel, delrin walls, 0.4 m/s, 0°)."""
    out = tmp_path_factory.mktemp("default")
    analysis = run_experiment(RunConfig(), out, log=lambda message: None)
    return out, analysis


@pytest.fixture(scope="session")
def dumped_run(tmp_path_factory):
    """The default experiment with ``--dump``: analysed in the run and its full dump on disk."""
    out = tmp_path_factory.mktemp("dumped")
    analysis = run_experiment(RunConfig(dump=True), out, log=lambda message: None)
    return out, analysis


@pytest.fixture(scope="session")
def launcher(tmp_path_factory):
    """(command, log): an MPI launcher that notes its arguments in ``log``, one line per job,
    and hands them to this environment's ``mpiexec`` (as ``mpiexec -f hosts`` or ``srun`` would)."""
    from hexdem.engines.lammps.library import environment_command

    folder = tmp_path_factory.mktemp("launcher")
    log, script = folder / "launched.log", folder / "launch"
    script.write_text(f'#!/bin/sh\nprintf "%s\\n" "$*" >> "{log}"\nexec "{environment_command("mpiexec")}" "$@"\n')
    script.chmod(0o755)
    return str(script), log


@pytest.fixture(scope="session")
def paper_quick(tmp_path_factory, launcher):
    """``hexdem paper --quick --launcher`` once per session (about a minute alone): its output
    directory. Every MPI job it started is in the launcher's log, which the session's other tests
    share: the paper's own jobs are also kept beside the output, in ``launched.log``."""
    from hexdem.cli.main import main

    out = tmp_path_factory.mktemp("paper") / "out"
    log = launcher[1]
    before = len(log.read_text().splitlines()) if log.exists() else 0
    assert main(["paper", "--out", str(out), "--quick", "--launcher", launcher[0]]) == 0
    (out.parent / "launched.log").write_text("".join(f"{job}\n" for job in log.read_text().splitlines()[before:]))
    return out


def record(engine, model, settings, directory, **options):
    """Run ``model`` with ``engine`` on one rank, keeping every sample: the whole trajectory (SI)."""
    recorder = TrajectoryRecorder(model, settings)
    return recorder.trajectory(engine.run(model, settings, directory, recorder, **options))


def single_bead(diameter_m=0.01905) -> Packing:
    """A one-bead 'packing' at the origin, for two-body collisions with a striker or a wall."""
    return Packing(
        labels=np.array([[0, 0]]),
        positions_m=np.zeros((1, 2)),
        diameters_m=np.array([diameter_m]),
        diameter_m=diameter_m,
        struck=0,
        walls=(),
        shape="single bead",
    )


def disordered_model(seed=1, edge_beads=3) -> GranularModel:
    """Beads of diameters in [0.999, 1] d on a lattice spaced for d, walls re-placed, a 20° striker."""
    lattice = hexagon(edge_beads, D)
    rng = np.random.default_rng(seed)
    lattice = lattice.with_geometry(lattice.positions_m, D * rng.uniform(0.999, 1.0, len(lattice)))
    return GranularModel(lattice, Impact(V0, angle_deg=20.0, striker=True), STEEL_316, DELRIN)


def contact_history(times, overlap):
    """(contact duration, peak overlap) of an overlap series that starts at 0 and ends negative."""
    k = int(np.flatnonzero(overlap[1:] < 0)[0]) + 1
    end = np.interp(0.0, overlap[[k, k - 1]], times[[k, k - 1]])
    return end, refine_peak(times, overlap)[1]


def settings_of(config: RunConfig):
    """The run settings of ``config`` on its own model."""
    return run_settings(config, build_model(config))


def contact_of(config: RunConfig) -> float:
    """The contact time [s] of ``config`` on its own model."""
    return contact_time_s(config, build_model(config))


def read_csv(path):
    """(header, rows as dicts) of a result table."""
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        return tuple(reader.fieldnames), list(reader)
