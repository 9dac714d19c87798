"""hexdem as users install it: the wheel of ``pip install .`` holds every module and template,
and, installed (not editable) into a fresh virtual environment, every command that starts MPI
ranks works from any directory: outside the checkout, in its root, and in a directory whose
own ``hexdem/`` would break the job if a rank imported it.

The fresh environment sees the wheel's declared dependencies (and theirs) as this environment
has them installed, linked rather than downloaded and unpacked again: an import the wheel does
not declare fails there as in a user's environment."""

import json
import os
import subprocess
import sys
import sysconfig
import zipfile
from email.parser import Parser
from importlib.machinery import EXTENSION_SUFFIXES
from importlib.metadata import distribution
from pathlib import Path

import pytest
from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow  # a wheel built and installed into a fresh environment: minutes


def wheel_names(wheel: Path) -> set[str]:
    return set(zipfile.ZipFile(wheel).namelist())


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel that ``pip install .`` builds from this checkout."""
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(out), str(ROOT)],
        check=True,
        capture_output=True,
    )
    (built,) = out.glob("hexdem-*.whl")
    return built


def declared(requirements, extras=()) -> list[Requirement]:
    """The ``requirements`` (Requires-Dist lines) that apply here with the ``extras`` asked for."""
    kept = [Requirement(text) for text in requirements]
    return [r for r in kept if r.marker is None or any(r.marker.evaluate({"extra": e}) for e in ("", *extras))]


def required_distributions(wheel: Path) -> list:
    """The installed distributions that the wheel's Requires-Dist needs, and theirs, transitively."""
    with zipfile.ZipFile(wheel) as archive:
        (metadata,) = [name for name in archive.namelist() if name.endswith(".dist-info/METADATA")]
        requirements = Parser().parsestr(archive.read(metadata).decode()).get_all("Requires-Dist")
    found, seen, todo = {}, set(), declared(requirements)
    while todo:
        requirement = todo.pop()
        if (requirement.name.lower(), frozenset(requirement.extras)) in seen:
            continue
        seen.add((requirement.name.lower(), frozenset(requirement.extras)))
        found[requirement.name.lower()] = dist = distribution(requirement.name)
        todo += declared(dist.requires or [], requirement.extras)
    return list(found.values())


def link_dependencies(wheel: Path, venv: Path) -> None:
    """Put every file of the wheel's required distributions (:func:`required_distributions`) in
    reach of ``venv``: their packages in a folder on its path (after its own site-packages, where
    the wheel's hexdem is), their files outside site-packages (mpiexec in bin/, libmpi in lib/) at
    the same place in ``venv``. The folder sits beside site-packages, so that a distribution's files
    outside it are found where its RECORD says (the mpich wheel's libmpi, which hexdem preloads)."""
    site = Path(sysconfig.get_path("purelib", vars={"base": str(venv), "platbase": str(venv)}))
    folder = site.with_name("dependencies")
    folder.mkdir()
    for dist in required_distributions(wheel):
        for file in dist.files or ():
            if file.parts[0] == "..":
                source = Path(os.path.normpath(dist.locate_file(file)))
                target = venv / source.relative_to(sys.prefix)
            else:
                source, target = Path(dist.locate_file(file.parts[0])), folder / file.parts[0]
            if not target.exists():
                target.parent.mkdir(parents=True, exist_ok=True)
                target.symlink_to(source)
    (site / "dependencies.pth").write_text(f"{folder}\n")


@pytest.fixture(scope="module")
def installed(wheel, tmp_path_factory) -> Path:
    """A fresh virtual environment with that wheel installed and its dependencies linked
    (:func:`link_dependencies`): its bin/."""
    venv = tmp_path_factory.mktemp("venv") / "env"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(venv / "bin" / "python"),
            "install",
            "-q",
            "--no-deps",
            str(wheel),
        ],
        check=True,
        capture_output=True,
    )
    link_dependencies(wheel, venv)
    return venv / "bin"


def test_the_fresh_environment_imports_the_wheels_hexdem_and_no_undeclared_package(installed):
    """The commands below run the wheel's hexdem, not this checkout's; a package that hexdem does
    not declare (pytest, here) is not importable there."""
    python = str(installed / "python")
    where = subprocess.run(
        [python, "-c", "import hexdem; print(hexdem.__file__)"],
        cwd=installed,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    assert Path(where).is_relative_to(installed.parent) and not Path(where).is_relative_to(ROOT), where
    assert subprocess.run([python, "-c", "import pytest"], cwd=installed, capture_output=True).returncode != 0


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
    modules = {
        path.relative_to(ROOT).as_posix()
        for path in (ROOT / "hexdem").rglob("*.py")
        if "lammps_inputs" not in path.parts
    }
    templates = {
        f"hexdem/lammps_inputs/{path.name}"
        for path in (ROOT / "lammps_inputs").iterdir()
        if path.suffix in (".in", ".py")
    }
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
    done = run(
        installed,
        cwd,
        "ensemble",
        "--realizations",
        "1",
        "--velocities",
        "0.4",
        "--edge-beads",
        "4",
        "--workers",
        "1",
        "--out",
        str(out),
    )
    assert done.returncode == 0, done.stderr
    assert json.loads((out / "ensemble.json").read_text())["config"]["realizations"] == 1
    assert (out / "peaks_stats.csv").exists()


def test_paper_help_from_any_directory(installed, cwd):
    done = run(installed, cwd, "paper", "--help")
    assert done.returncode == 0 and "--launcher" in done.stdout and "--quick" in done.stdout
