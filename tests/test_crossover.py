"""The crossover of weak disorder: the step fit, the V^(4/5) test, the overlap scale, and the sweep
in ``hexdem paper --quick``."""

import csv
import json

import numpy as np
import pytest
from readable import saved_figure, smallest_text_px

from hexdem.disorder.preparation import TOLERANCE_M
from hexdem.paper.crossover import (
    CROSSOVER_COLUMNS,
    CROSSOVER_FIGURES,
    _step,
    crossover_figure,
    crossover_fits,
    crossover_rows,
    fit_crossover,
    impact_overlap_m,
    overlap_test,
)
from hexdem.paper.settings import PaperSettings

SIGMA_TOL = np.geomspace(1e-3, 6.0, 9)


def test_the_impact_overlap_is_hertzs_and_scales_as_v_to_the_four_fifths():
    """δ = (5 μ V² / 4A)^{2/5}: two 19.05 mm steel beads (m = 28.96 g, A = (4/3) E/(2(1 − ν²)) sqrt(d/4))."""
    d, e, nu, rho = 0.01905, 193e9, 0.3, 8000.0
    mass = rho * np.pi * d**3 / 6
    a = 4 / 3 * e / (2 * (1 - nu**2)) * np.sqrt(d / 4)
    assert impact_overlap_m(0.4) == pytest.approx((5 * mass / 2 * 0.4**2 / (4 * a)) ** 0.4, rel=1e-12)
    assert impact_overlap_m(0.7) / impact_overlap_m(0.25) == pytest.approx((0.7 / 0.25) ** 0.8, rel=1e-12)


def test_the_step_fit_recovers_a_known_crossover_and_finds_none_in_a_flat_curve():
    t = _step(np.log10(SIGMA_TOL), 0.91, 0.57, np.log10(0.05), 1.5)
    fit = fit_crossover(SIGMA_TOL, t, np.full(9, 0.01))
    assert fit["significant"] and fit["sigma_c_tol"] == pytest.approx(0.05, rel=1e-6)
    assert fit["drop"] == pytest.approx(0.34, abs=1e-6) and fit["p"] == pytest.approx(1.5, rel=1e-5)
    # a standard error of 0.01 in each point leaves σ_c known to a fraction of a decade, not exactly
    assert 0 < fit["log10_sigma_c_se"] < 0.5
    flat = fit_crossover(SIGMA_TOL, 0.8 + 0.005 * np.sin(np.arange(9)), np.full(9, 0.01))
    assert not flat["significant"] and np.isnan(flat["sigma_c_tol"])


def summaries_with(crossover_tol_at):
    """Ensemble summaries whose transmission steps from 0.9 to 0.6 at σ_c(V) = ``crossover_tol_at(V)``."""
    out = []
    for sigma in SIGMA_TOL:
        effects = [
            {
                "v_striker": v,
                "line": line,
                "mean_ratio": float(_step(np.log10(sigma), 0.9, 0.6, np.log10(crossover_tol_at(v)), 2.0)),
                "sem_ratio": 0.01,
                "std_ratio": 0.045,
                "realizations": 20,
            }
            for v in (0.25, 0.4, 0.7)
            for line in ("0", "+30", "±30")
        ]
        out.append(
            {
                "sigma_per_tol": float(sigma),
                "preparation": "prestressed",
                "disorder_effect": effects,
                "leading_pulse_effect": effects,
            }
        )
    return out + [{"sigma_per_tol": 6.0, "preparation": "relaxed", "disorder_effect": [], "leading_pulse_effect": []}]


@pytest.mark.parametrize("exponent", [0.8, 0.0])
def test_the_overlap_test_tells_a_v_to_the_four_fifths_crossover_from_a_fixed_one(exponent):
    rows = crossover_rows(summaries_with(lambda v: 0.1 * (v / 0.4) ** exponent))
    assert {r[1] for r in rows} == {"0", "±30"} and len(rows) == 9 * 3 * 2 * 2  # σ, V, line, measure
    row = next(r for r in rows if r[0] == 0.7 and r[3] == SIGMA_TOL[4])
    assert row[4] == pytest.approx(SIGMA_TOL[4] * TOLERANCE_M / impact_overlap_m(0.7), rel=1e-12)
    tests = overlap_test(crossover_fits(rows))
    assert len(tests) == 4
    for test in tests:
        assert test["slope"] == pytest.approx(exponent, abs=1e-4)
        assert test["consistent_with_overlap"] is (exponent == 0.8)
        assert test["consistent_with_constant"] is (exponent == 0.0)


@pytest.mark.parametrize("against", list(CROSSOVER_FIGURES))
def test_the_crossover_figures_are_readable_in_the_reports_column(monkeypatch, against):
    """Four panels a figure, its smallest text at least 10 px where the report shows it (the
    eight panels of one 16-inch figure had 8-point text shrunk to 7.8 px)."""
    rows = crossover_rows(summaries_with(lambda v: 0.1 * (v / 0.4) ** 0.8))
    fig = saved_figure(monkeypatch, lambda: crossover_figure(rows, crossover_fits(rows), "unused.png", against))
    assert len(fig.axes) == 4
    assert smallest_text_px(fig) >= 10


def test_the_quick_paper_writes_the_crossover_sweep(paper_quick):
    folder = paper_quick / "disorder"
    with open(folder / "disorder_crossover.csv", newline="") as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
    assert tuple(reader.fieldnames) == CROSSOVER_COLUMNS
    sigmas = {float(r["sigma_tol"]) for r in rows}
    assert set(PaperSettings(quick=True).crossover_sigma_per_tol) <= sigmas
    assert {float(r["v_striker"]) for r in rows} == {0.25, 0.4, 0.7}
    result = json.loads((folder / "disorder_crossover.json").read_text())
    assert len(result["fits"]) == 3 * 2 * 2 and len(result["overlap_test"]) == 4 and result["verdict"]
    assert all((folder / name).stat().st_size > 0 for name in CROSSOVER_FIGURES.values())
    assert result["pm30_claim"] in (paper_quick / "report.md").read_text()
