"""The basins-and-interfaces workflow runs in one command and writes its page, tables and movies."""

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

WORKFLOW = Path(__file__).resolve().parents[1] / "workflows" / "basins_and_interfaces.py"


@pytest.mark.slow
def test_the_basins_and_interfaces_workflow_runs_in_one_command(tmp_path):
    done = subprocess.run([sys.executable, str(WORKFLOW), "--out", str(tmp_path), "--quick"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    cases = json.loads((tmp_path / "workflow.json").read_text())["cases"]
    assert list(cases) == ["hexagon", "triangle", "disc", "steel_brass", "steel_ptfe", "double_strike",
                           "flat_striker", "ring"]
    page = (tmp_path / "index.html").read_text()
    for case in cases:
        assert (tmp_path / case / "movie.gif").read_bytes()[:6] == b"GIF89a"
        assert f"{case}/movie.gif" in page and f"{case}/peak_map.png" in page
    with open(tmp_path / "interfaces.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert {row["case"] for row in rows} == {"steel_brass", "steel_ptfe"}
    for case in ("steel_brass", "steel_ptfe"):  # all on the struck side at first, then some goes across
        series = [row for row in rows if row["case"] == case]
        assert float(series[0]["time_ms"]) == 0.0 and float(series[0]["far_side_fraction"]) == 0.0
        assert float(series[-1]["far_side_fraction"]) > 0.05
    trapping = json.loads((tmp_path / "trapping.json").read_text())
    assert set(trapping) == {"steel_brass", "steel_ptfe"}, "one entry per interface case"
    assert all(0.0 < t["far_side_fraction_end"] <= t["far_side_fraction_max"] < 1.0 for t in trapping.values())
