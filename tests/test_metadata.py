"""The licence and the citation say what pyproject.toml says, so they cannot drift apart."""

import re
import tomllib
from pathlib import Path

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
