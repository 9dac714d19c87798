"""``hexdem paper --quick``: the whole pipeline once (the session's), its report and table
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
from hexdem.paper.friction_study import EFFECT_COLUMNS, arrival_verdict
from hexdem.paper.published import PUBLISHED
from hexdem.paper.settings import PaperSettings
from hexdem.theory.outputs import read_sweep_peaks
from hexdem.theory.scaling import fit_decay

#: What the quick run computes: its σ, μ, V₀ and packings.
QUICK = PaperSettings(quick=True)


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


def test_the_closest_protocol_refits_to_its_reported_line(quick):
    """Redo each combination's closest protocol by hand from peaks.csv: per-V0 decay fits on its
    window, then np.polyfit over its V0 range, independently of the search's prefix sums."""
    v0, peaks = read_sweep_peaks(quick / "scaling")
    closest = [r for r in table(quick / "fit_protocols" / "fit_protocols.csv") if r["role"] == "closest_1"]
    assert sorted(r["combination"] for r in closest) == sorted(("30/30", "30/0", "0/0", "0/30"))
    for row in closest:
        line = peaks[row["combination"]]
        chosen = (v0 >= float(row["v0_min"])) & (v0 <= float(row["v0_max"]))
        assert np.count_nonzero(chosen) == int(row["n_v0"])
        c = [
            fit_decay(
                np.arange(line.shape[1]), p, int(row["start"]), int(row["last"]), row["fit"], row["anchored"] == "True"
            )[0]
            for p in line[chosen]
        ]
        m, b = np.polyfit(v0[chosen], c, 1)
        assert m == pytest.approx(float(row["m"]), rel=1e-8) and b == pytest.approx(float(row["b"]), rel=1e-10)


def test_the_disorder_study_covers_every_strength_and_reaches_a_verdict(quick):
    rows = table(quick / "disorder" / "disorder_study.csv")
    prestressed = {
        (float(r["sigma_per_tol"]), r["measure"], r["line"]) for r in rows if r["preparation"] == "prestressed"
    }
    assert prestressed == {(s, m, line) for s in QUICK.sigma_per_tol for m in ("peak", "lead") for line in ("0", "±30")}
    study = json.loads((quick / "disorder" / "disorder_study.json").read_text())
    assert study["verdict"]["summary"] and study["verdict"]["paper_case"]["sigma_per_tol"] == 6
    report = (quick / "report.md").read_text()
    assert study["verdict"]["summary"] in report


def test_the_prestress_variant_is_free_of_the_compactions_load(quick):
    """Equal beads: the paper's walls keep the 5 N compaction's load, stood-back walls only
    the weight along the 5° tilt (3k(k − 1) + 1 beads of k per edge × 28.9 g × 0.855 m/s²: 8.2 N
    for the experiment's 331, 3.1 N for the quick run's 127, spread over slanted walls)."""
    load = {
        (float(r["sigma_per_tol"]), r["preparation"]): float(r["wall_force_n"])
        for r in table(quick / "disorder" / "prestress.csv")
    }
    k = QUICK.ensemble_edge_beads
    weight = (3 * k * (k - 1) + 1) * 8000 * math.pi * 0.01905**3 / 6 * 9.80665 * math.sin(math.radians(5))
    assert load[(0.0, "relaxed")] < 2 * weight < load[(0.0, "prestressed")]


def test_the_html_report_is_self_contained_with_every_figure(quick):
    page = (quick / "report.html").read_text()
    sources = re.findall(r'src="([^"]*)"', page)
    assert len(sources) >= 10 and all(s.startswith("data:image/png;base64,") for s in sources)
    assert "published" in page and "Verdict" in page


def test_a_rerun_resumes_without_recomputing(quick, capsys):
    markers = sorted((quick / "parts").glob("*.json"))
    assert {"tca", "fig3", "fig4", "scaling", "fit_protocols", "disorder", "crossover", "friction"} <= {
        p.stem for p in markers
    }
    before = {p.name: p.stat().st_mtime_ns for p in markers}
    assert main(["paper", "--out", str(quick), "--quick"]) == 0
    err = capsys.readouterr().err
    skipped = re.findall(r"\[\d+/(\d+)\] [^\n]*: done before", err)
    assert len(skipped) == len(markers) == int(skipped[0]), "every part of the run was done before"
    assert {p.name: p.stat().st_mtime_ns for p in sorted((quick / "parts").glob("*.json"))} == before


def test_every_mpi_job_of_the_paper_went_through_the_launcher(quick):
    """Fig. 3 on 1 rank and Fig. 4 on 2, each run of the V0 sweep, each of the ensembles'
    preparation decks and impacts on one rank: the jobs the paper's run started (the session's
    launcher log also holds other tests' jobs)."""
    jobs = (quick.parent / "launched.log").read_text().splitlines()
    for folder, ranks in (("fig3", 1), ("fig4", 2)):
        assert [job.split()[:2] for job in jobs if f"{quick}/{folder}/" in job] == [["-n", str(ranks)]], folder
    impacts = [job for job in jobs if f"{quick}/disorder/sigma6tol/" in job and "/v0." in job]
    assert impacts and all(job.startswith("-n 1 ") for job in impacts), "the impacts"
    assert sum("hexdem-scaling-" in job for job in jobs) == 2 * QUICK.n_v0, "the V0 sweep"
    decks = [job for job in jobs if job.endswith("-in in.hexdem -log log.lammps -screen none -nocite")]
    assert decks and all(job.startswith("-n 1 ") for job in decks), "the ensembles' preparation"


def test_the_friction_study_covers_every_friction_speed_and_line(quick):
    with open(quick / "friction" / "friction_effect.csv", newline="") as fh:
        assert tuple(next(csv.reader(fh))) == EFFECT_COLUMNS
    rows = table(quick / "friction" / "friction_effect.csv")
    keys = {(float(r["friction"]), float(r["v_striker"]), float(r["sigma_tol"]), r["line"]) for r in rows}
    assert keys == {
        (mu, v, s, line)
        for mu in (0.0, *QUICK.frictions)
        for v in (0.25, 0.40, 0.70)
        for s in (0.0, 6.0)
        for line in ("0", "±30")
    } and len(rows) == len(keys)
    study = json.loads((quick / "friction" / "friction_study.json").read_text())
    report = (quick / "report.md").read_text()
    assert "Friction and rotation" in report and "friction/friction_effect.png" in report
    assert study["arrival_verdict"] in report and study["disorder_verdict"] in report


def test_friction_strikes_the_papers_packings_and_only_the_impacts_differ(quick):
    """The frictional ensembles adopt the σ = 6 tol ensemble's settled packings (not prepared
    again) and strike them with nve/sphere."""
    for mu in QUICK.frictions:
        for k in range(QUICK.friction_realizations):
            ours = np.load(quick / "friction" / f"friction{mu:g}" / "realizations" / f"r{k:04d}" / "result.npz")
            paper = np.load(quick / "disorder" / "sigma6tol" / "realizations" / f"r{k:04d}" / "result.npz")
            np.testing.assert_array_equal(ours["positions_m"], paper["positions_m"])
            assert not np.array_equal(ours["lead_speed"], paper["lead_speed"], equal_nan=True)


def test_friction_in_the_ideal_lattice_does_not_depend_on_the_speed(quick):
    """Hertz–Mindlin–Coulomb is homogeneous: F_n ∝ δ^(3/2), F_t ∝ a ξ ∝ δ^(1/2) ξ, and the cap μ F_n
    scales with F_n, so x → λx, t → λ^(−1/4) t maps a run at one striker speed onto another's
    (the frictionless one too). Ratios to the frictionless run, and Sec. V's decay rates, are then
    the same at every speed, up to the geometric nonlinearity δ/d ≤ 8e-4 (δ = 15 µm at 0.70 m/s)
    and the arrival shifts scale as V^(−1/5)."""
    rows = table(quick / "friction" / "friction_effect.csv")
    ideal = {(float(r["friction"]), float(r["v_striker"]), r["line"]): r for r in rows if float(r["sigma_tol"]) == 0}
    for mu in QUICK.frictions:
        for line in ("0", "±30"):
            ratios = [float(ideal[mu, v, line]["mean_peak_ratio"]) for v in (0.25, 0.40, 0.70)]
            assert max(ratios) - min(ratios) < 1e-3 * max(ratios)
            assert abs(ratios[0] - 1) > 1e-2, "friction changes the leading pulse"
            shifts = [float(ideal[mu, v, line]["mean_arrival_shift_us"]) * v**0.2 for v in (0.25, 0.40, 0.70)]
            assert max(shifts) - min(shifts) < 1e-2 * max(abs(s) for s in shifts)
    decay = table(quick / "friction" / "friction_decay.csv")
    for mu in (0.0, *QUICK.frictions):
        for combination in ("0/0", "0/30"):
            rates = [
                float(r["decay_rate"]) for r in decay if float(r["friction"]) == mu and r["combination"] == combination
            ]
            assert len(rates) == 3 and max(rates) - min(rates) < 1e-3 * max(rates)


def test_the_arrival_verdict_names_the_lines_friction_delays():
    def row(mu, line, shift):
        return (mu, 0.40, 0.0, line, 0.9, float("nan"), shift)

    mixed = arrival_verdict([row(0.1, "0", -3.0), row(0.1, "±30", 2.0), row(0.5, "0", -20.0), row(0.5, "±30", 9.0)])
    assert "delays the arrivals along ±30° but brings them forward along 0°" in mixed
    assert "μ = 0.5: 0° -20.00 µs, ±30° +9.00 µs" in mixed
    later = arrival_verdict([row(0.1, "0", 1.0), row(0.1, "±30", 2.0)])
    assert "in the direction of the experiment's longer arrival times" in later


def test_other_settings_in_the_same_directory_are_refused(quick, capsys):
    assert main(["paper", "--out", str(quick)]) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "other settings" in lines[0]


def test_bad_workers_is_one_clear_line(tmp_path, capsys):
    assert main(["paper", "--out", str(tmp_path / "out"), "--workers", "0", "--quick"]) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "--workers must be a positive integer" in lines[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "mean, sem, realizations, expected",
    [
        (1.10, 0.02, 20, "rises"),
        (1.03, 0.02, 20, "unchanged"),
        (0.90, 0.02, 20, "falls"),
        (1.01, float("nan"), 1, "rises"),
        (1.01, float("nan"), 20, "undetermined"),
        (float("nan"), 0.1, 20, "undetermined"),
    ],
)
def test_a_change_counts_only_beyond_two_standard_errors(mean, sem, realizations, expected):
    assert change(mean, sem, realizations) == expected


def test_the_verdict_names_the_conditions_of_the_papers_claim():
    def row(sigma, preparation, line, ratio, sem=0.01):
        return (sigma, 0.0, preparation, "peak", line, ratio, sem, sem * 4, 20, ratio)

    rows = [
        row(6.0, "prestressed", "±30", 0.80),
        row(6.0, "prestressed", "0", 0.70),
        row(6.0, "relaxed", "±30", 1.10),
        row(6.0, "relaxed", "0", 0.90),
    ]
    result = verdict(rows)
    assert [(c["sigma_per_tol"], c["preparation"]) for c in result["rises_at"]] == [(6.0, "relaxed")]
    assert result["paper_case"]["pm30"] == "falls" and "relaxed" in result["summary"]
    assert result["summary"].startswith("At σ = 6 tol (the study's strengths, 0.40 m/s"), "its σ range stated"
    assert verdict(
        [r for r in rows if r[2] == "prestressed"]
        + [row(1.0, "prestressed", "±30", 0.9), row(1.0, "prestressed", "0", 0.9)]
    )["summary"].startswith("At σ = 1, 6 tol")
    assert np.isclose(result["paper_case"]["pm30_ratio"], 0.80)
    assert len(STUDY_COLUMNS) == len(rows[0])
