"""The workflows run in one command and write their pages, tables and movies: basins and
interfaces, and the Dirac point."""

import csv
import html
import json
import subprocess
import sys
from pathlib import Path

import pytest

WORKFLOW = Path(__file__).resolve().parents[1] / "workflows" / "basins_and_interfaces.py"


@pytest.mark.slow
def test_the_basins_and_interfaces_workflow_runs_in_one_command(tmp_path):
    done = subprocess.run(
        [sys.executable, str(WORKFLOW), "--out", str(tmp_path), "--quick"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    cases = json.loads((tmp_path / "workflow.json").read_text())["cases"]
    assert list(cases) == [
        "hexagon",
        "triangle",
        "disc",
        "steel_brass",
        "steel_ptfe",
        "double_strike",
        "flat_striker",
        "ring",
    ]
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


DIRAC_WORKFLOW = WORKFLOW.parent / "dirac_point.py"


@pytest.mark.slow
def test_the_dirac_point_workflow_writes_its_tables_within_the_bounds(tmp_path):
    """``--quick`` (20 per edge, σ = 8 d, the small sweep) on one rank from another directory: the
    contract's files and columns (the dispersion's first six as before, each point's verdict after
    them), the dispersion within 2 % (median) and every point beyond the resolution limit within its
    bound, and the ring's growth within 3 % of v_D, the ring opened past 2.5 σ, and the control away
    from K drifting at its group velocity within 2 % and widening by less than 10 %."""
    done = subprocess.run(
        [sys.executable, str(DIRAC_WORKFLOW), "--out", str(tmp_path / "out"), "--quick", "--ranks", "1"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    out = tmp_path / "out"
    result = json.loads((out / "dirac_point.json").read_text())
    assert result["dispersion"]["median_relative_deviation"] <= 0.02
    assert result["dispersion"]["within_bound"] and result["dispersion"]["every_resolved_point_within_bound"]
    assert result["dispersion"]["largest_resolved_relative_deviation"] <= result["dispersion"]["largest_resolved_bound"]
    assert result["conical"]["slope_relative_deviation"] <= 0.03
    assert result["conical"]["control_drift_relative_deviation"] < 0.02 and result["conical"]["control_widening"] < 0.10
    with open(out / "conical.csv", newline="") as fh:
        assert float(list(csv.DictReader(fh))[-1]["ring_radius_d"]) > 2.5 * 8.0  # σ = 8 d
    headers = {name: next(csv.reader(open(out / name))) for name in ("dispersion.csv", "conical.csv", "transition.csv")}
    assert headers["dispersion.csv"] == [
        "path_position",
        "kx",
        "ky",
        "branch",
        "omega_theory",
        "omega_measured",
        "relative_deviation",
        "bound",
        "resolved",
        "within_bound",
    ]
    assert headers["conical.csv"] == ["time_s", "ring_radius_d", "theory_radius_d"]
    assert headers["transition.csv"][:2] == ["precompression_n", "v0_m_s"]
    assert (out / "conical.gif").read_bytes()[:6] == b"GIF89a"
    page = (out / "dirac_point.html").read_text()
    assert page.count("data:image/png;base64,") == 4 and html.escape(result["transition"]["finding"]) in page


def test_the_dirac_point_workflow_refuses_an_unwritable_out_in_one_line(tmp_path):
    (tmp_path / "file").write_text("")
    done = subprocess.run(
        [sys.executable, str(DIRAC_WORKFLOW), "--out", str(tmp_path / "file" / "out"), "--quick"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 3 and len(done.stderr.strip().splitlines()) == 1, done.stderr  # refused input
