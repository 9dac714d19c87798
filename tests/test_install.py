"""hexdem as users install it: the wheel of ``pip install .`` holds every module and template,
and, installed (not editable) into a fresh virtual environment, every command that starts MPI
ranks works from any directory: outside the checkout, in its root, and in a directory whose
own ``hexdem/`` would break the job if a rank imported it."""

import json
import subprocess
import sys
import zipfile
from importlib.machinery import EXTENSION_SUFFIXES
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow  # a wheel built and installed into a fresh environment: minutes


def wheel_names(wheel: Path) -> set[str]:
    return set(zipfile.ZipFile(wheel).namelist())


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel that ``pip install .`` builds from this checkout."""
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(out), str(ROOT)],
                   check=True, capture_output=True)
    (built,) = out.glob("hexdem-*.whl")
    return built


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> Path:
    """A fresh virtual environment with that wheel (and its dependencies) installed: its bin/."""
    venv = tmp_path_factory.mktemp("venv") / "env"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    subprocess.run([str(venv / "bin" / "python"), "-m", "pip", "install", "-q", str(wheel)], check=True,
                   capture_output=True)
    return venv / "bin"


@pytest.fixture(scope="module", params=["outside", "checkout root", "foreign hexdem"])
def cwd(request, tmp_path_factory) -> Path:
    """Where the user stands: anywhere, the clone's root, or beside a ``hexdem/`` that fails on import."""
    if request.param == "checkout root":
        return ROOT
    here = tmp_path_factory.mktemp("cwd")
    if request.param == "foreign hexdem":
        (here / "hexdem").mkdir()
        (here / "hexdem" / "__init__.py").write_text("raise ImportError('a rank imported ./hexdem')\n")
    return here


def run(bin_dir: Path, cwd: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(bin_dir / "hexdem"), *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_wheel_holds_every_module_and_template(wheel):
    names = wheel_names(wheel)
    modules = {path.relative_to(ROOT).as_posix() for path in (ROOT / "hexdem").rglob("*.py")
               if "lammps_inputs" not in path.parts}
    templates = {f"hexdem/lammps_inputs/{path.name}" for path in (ROOT / "lammps_inputs").iterdir()
                 if path.suffix in (".in", ".py")}
    assert "hexdem/paper/pipeline.py" in modules and "hexdem/lammps_inputs/impact.in" in templates
    assert sorted(modules - names) == [] and sorted(templates - names) == []
    # the in-run analysis's C kernels, built by pip for this Python
    assert any(f"hexdem/common/_kernels{suffix}" in names for suffix in EXTENSION_SUFFIXES)


def test_run_on_two_ranks_from_any_directory(installed, cwd, tmp_path):
    done = run(installed, cwd, "run", "--ranks", "2", "--out", str(tmp_path / "run"))
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["ranks"] == 2 and summary["far_wall_reached"] is True


def test_one_realization_ensemble_from_any_directory(installed, cwd, tmp_path):
    out = tmp_path / "ensemble"
    done = run(installed, cwd, "ensemble", "--realizations", "1", "--velocities", "0.4", "--edge-beads", "4",
               "--workers", "2", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert json.loads((out / "ensemble.json").read_text())["config"]["realizations"] == 1
    assert (out / "peaks_stats.csv").exists()


def test_paper_help_from_any_directory(installed, cwd):
    done = run(installed, cwd, "paper", "--help")
    assert done.returncode == 0 and "--launcher" in done.stdout and "--quick" in done.stdout
