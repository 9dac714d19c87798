"""``hexdem paper --quick``: the whole pipeline once (about two minutes), its report and table
against the paper and the theory, resuming, and refusals."""

import csv
import json
import math
import re

import numpy as np
import pytest

from hexdem.cli.main import main
from hexdem.paper.comparison import COMPARISON_COLUMNS
from hexdem.paper.disorder_study import STUDY_COLUMNS, change, verdict
from hexdem.paper.published import PUBLISHED
from hexdem.paper.settings import SIGMA_PER_TOL


@pytest.fixture
def quick(paper_quick):
    return paper_quick


def table(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_every_published_number_has_a_computed_one_and_its_protocol(quick):
    with open(quick / "published_vs_computed.csv", newline="") as fh:
        assert tuple(next(csv.reader(fh))) == COMPARISON_COLUMNS
    rows = table(quick / "published_vs_computed.csv")
    assert [(r["quantity"], r["combination"]) for r in rows] == [(p.quantity, p.combination) for p in PUBLISHED]
    for row in rows:
        published, computed = float(row["published"]), float(row["computed"])
        assert float(row["difference"]) == pytest.approx(computed - published, abs=1e-12)
        assert row["protocol"] and row["combination"] in ("", "30/30", "30/0", "0/0", "0/30")
    omega, c = rows[0], rows[1]
    assert float(omega["computed"]) == pytest.approx((3 - math.sqrt(5)) / 2, abs=1e-9)  # eq. for ω: ω = (3 − √5)/2
    assert abs(float(omega["difference"])) < 5e-4 and abs(float(c["difference"])) < 5e-4


def test_the_laws_in_the_table_are_those_of_the_scaling_step_and_its_stated_protocol(quick):
    scaling = json.loads((quick / "scaling" / "scaling.json").read_text())
    protocols = table(quick / "fit_protocols" / "fit_protocols.csv")
    for row in table(quick / "published_vs_computed.csv")[2:]:
        assert float(row["computed"]) == pytest.approx(scaling[row["combination"]][row["quantity"]], rel=1e-12)
        if row["quantity"] in ("m", "b"):
            stated = next(p for p in protocols if p["role"] == "stated" and p["combination"] == row["combination"])
            assert float(stated[row["quantity"]]) == pytest.approx(float(row["computed"]), rel=1e-9)


def test_the_closest_protocol_is_no_farther_than_the_stated_one(quick):
    summary = json.loads((quick / "fit_protocols" / "fit_protocols.json").read_text())
    for name, entry in summary.items():
        assert entry["closest"]["distance"] <= entry["stated"]["distance"]
        assert entry["consistent"]["count"] <= entry["protocols"]


def test_the_disorder_study_covers_every_strength_and_reaches_a_verdict(quick):
    rows = table(quick / "disorder" / "disorder_study.csv")
    prestressed = {(float(r["sigma_per_tol"]), r["measure"], r["line"]) for r in rows if r["preparation"] == "prestressed"}
    assert prestressed == {(s, m, line) for s in SIGMA_PER_TOL for m in ("peak", "lead") for line in ("0", "±30")}
    for r in rows:
        if float(r["sigma_per_tol"]) == 0:
            assert float(r["ratio_to_equal_beads"]) == pytest.approx(1.0)
    study = json.loads((quick / "disorder" / "disorder_study.json").read_text())
    assert study["verdict"]["summary"] and study["verdict"]["paper_case"]["sigma_per_tol"] == 6
    report = (quick / "report.md").read_text()
    assert study["verdict"]["summary"] in report


def test_the_prestress_variant_is_free_of_the_compactions_load(quick):
    """Equal beads: the paper's walls keep the 5 N compaction's load, stood-back walls only
    the weight along the 5° tilt (331 beads × 28.9 g × 0.855 m/s² ≈ 8.2 N, spread over slanted walls)."""
    load = {(float(r["sigma_per_tol"]), r["preparation"]): float(r["wall_force_n"])
            for r in table(quick / "disorder" / "prestress.csv")}
    weight = 331 * 8000 * math.pi * 0.01905**3 / 6 * 9.80665 * math.sin(math.radians(5))
    assert load[(0.0, "relaxed")] < 2 * weight < load[(0.0, "prestressed")]


def test_the_html_report_is_self_contained_with_every_figure(quick):
    page = (quick / "report.html").read_text()
    sources = re.findall(r'src="([^"]*)"', page)
    assert len(sources) >= 10 and all(s.startswith("data:image/png;base64,") for s in sources)
    assert "published" in page and "Verdict" in page


def test_a_rerun_resumes_without_recomputing(quick, capsys):
    markers = sorted((quick / "parts").glob("*.json"))
    before = {p.name: p.stat().st_mtime_ns for p in markers}
    assert main(["paper", "--out", str(quick), "--quick"]) == 0
    err = capsys.readouterr().err
    assert err.count("done before") == len(markers)
    assert {p.name: p.stat().st_mtime_ns for p in sorted((quick / "parts").glob("*.json"))} == before


def test_other_settings_in_the_same_directory_are_refused(quick, capsys):
    assert main(["paper", "--out", str(quick)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "other settings" in lines[0]


def test_bad_workers_is_one_clear_line(tmp_path, capsys):
    assert main(["paper", "--out", str(tmp_path / "out"), "--workers", "0", "--quick"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "--workers must be a positive integer" in lines[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("mean, sem, expected", [
    (1.10, 0.02, "rises"), (1.03, 0.02, "unchanged"), (0.90, 0.02, "falls"), (1.01, float("nan"), "rises")])
def test_a_change_counts_only_beyond_two_standard_errors(mean, sem, expected):
    assert change(mean, sem) == expected


def test_the_verdict_names_the_conditions_of_the_papers_claim():
    def row(sigma, preparation, line, ratio, sem=0.01):
        return (sigma, 0.0, preparation, "peak", line, ratio, sem, sem * 4, 20, ratio)

    rows = [row(6.0, "prestressed", "±30", 0.80), row(6.0, "prestressed", "0", 0.70),
            row(6.0, "relaxed", "±30", 1.10), row(6.0, "relaxed", "0", 0.90)]
    result = verdict(rows)
    assert [(c["sigma_per_tol"], c["preparation"]) for c in result["rises_at"]] == [(6.0, "relaxed")]
    assert result["paper_case"]["pm30"] == "falls" and "relaxed" in result["summary"]
    assert np.isclose(result["paper_case"]["pm30_ratio"], 0.80)
    assert len(STUDY_COLUMNS) == len(rows[0])
