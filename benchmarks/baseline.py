"""The "before" of a side-by-side benchmark: hexdem as it was at an earlier revision of this clone.

:func:`baseline_tree` unpacks the package of ``revision`` (default :data:`BEFORE`, the last
commit before the speed work) from this clone's git history into a scratch directory;
:func:`hexdem_command` and :func:`hexdem_env` run either version the same way, as
``python -m hexdem.cli.main`` from a scratch working directory, the earlier one first on
``PYTHONPATH`` (so its MPI ranks import it too), in the same environment and on the same
machine load. The earlier version runs as its users ran it: without the BLAS thread limit
that today's hexdem sets for itself.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

#: The last commit before the speed work (issue: the analysis costs less than the simulation).
BEFORE = "e8fb865"
ROOT = Path(__file__).resolve().parents[1]
#: The environment variable naming a folder that keeps the unpacked revisions from one benchmark
#: to the next (the test suite's quick runs share one); unset, each benchmark unpacks its own.
KEPT_ENV = "HEXDEM_BENCH_BASELINES"


def baseline_tree(work: Path, revision: str = BEFORE) -> Path | None:
    """The package of ``revision`` unpacked under ``work`` (its ``lammps_inputs`` link made a
    copy; a revision with C kernels, ``hexdem/common/kernels``, installed there by pip, which
    builds them) and warmed up, or None when this clone does not hold that revision (a shallow
    clone).

    The warm-up, a small ``hexdem run``, fills the unpacked package's numba cache as a user's
    first run would, so that no timed run of the earlier version compiles its kernels. With
    ``$HEXDEM_BENCH_BASELINES`` set (:data:`KEPT_ENV`) the tree is unpacked there instead of under
    ``work``, once: a later call finds it warmed up and returns it."""
    kept = os.environ.get(KEPT_ENV)
    if kept:
        work = Path(kept) / revision
        if (work / f"hexdem-{revision}" / "warm-up").is_dir():
            return work / f"hexdem-{revision}"
        shutil.rmtree(work, ignore_errors=True)  # an unpacking cut short
    source = Path(work) / f"source-{revision}"
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", revision, "hexdem", "lammps_inputs", "pyproject.toml", "README.md"],
        capture_output=True,
        check=False,
    )
    if archive.returncode != 0:
        return None
    source.mkdir(parents=True)
    subprocess.run(["tar", "-x", "-C", str(source)], input=archive.stdout, check=True)
    target = Path(work) / f"hexdem-{revision}"
    if (source / "hexdem" / "common" / "kernels").is_dir():
        subprocess.run(
            [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target), str(source)],
            capture_output=True,
            check=True,
        )
    else:
        target.mkdir()
        shutil.move(source / "hexdem", target / "hexdem")
        inputs = target / "hexdem" / "lammps_inputs"
        if inputs.is_symlink():
            inputs.unlink()
            shutil.copytree(source / "lammps_inputs", inputs)
    config = target / "warm-up.toml"
    config.write_text("edge_beads = 4\nduration = 1e-4\n")
    subprocess.run(
        hexdem_command("run", "--config", str(config), "--out", str(target / "warm-up")),
        cwd=target,
        env=hexdem_env(target),
        capture_output=True,
        check=True,
    )
    return target


def hexdem_command(*args: str) -> list[str]:
    """``hexdem ARGS`` as a module run, the same for either version (see :func:`hexdem_env`)."""
    return [sys.executable, "-m", "hexdem.cli.main", *args]


def hexdem_env(tree: Path | None) -> dict:
    """The environment of a run of the earlier version unpacked at ``tree`` (None: today's)."""
    env = dict(os.environ)
    if tree is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(tree), *filter(None, [env.get("PYTHONPATH")])])
        env.pop("OPENBLAS_NUM_THREADS", None)
    return env
