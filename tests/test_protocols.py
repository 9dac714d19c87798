"""The fit-protocol search (hexdem.theory.protocols) and the free-start decay fit, on data
whose decay law is known exactly."""

import numpy as np
import pytest
from test_scaling import TRUE, V0, synthetic_peaks

from hexdem.theory import protocols, scaling

#: The exact law, published to 12 digits.
EXACT = protocols.Target(TRUE["m"], TRUE["b"], 5e-13, 5e-13)


def test_line_fits_over_every_range_equal_ordinary_least_squares():
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0.01, 0.3, 12))
    y = 0.85 + 0.2 * x + 0.01 * rng.standard_normal(12)
    first, final, m, m_err, b, b_err = protocols.line_fits_over_ranges(x, y, min_points=4)
    assert len(m) == sum(12 - size + 1 for size in range(4, 13))
    for i, j, *values in zip(first, final, m, m_err, b, b_err):
        fit = scaling.polynomial_fit(x[i : j + 1], y[i : j + 1], 1, ("m", "b"))
        np.testing.assert_allclose(values, [fit["m"], fit.error("m"), fit["b"], fit.error("b")], rtol=1e-8)


@pytest.mark.parametrize("kind", scaling.FIT_KINDS)
def test_free_and_anchored_starts_agree_on_an_exact_geometric_decay(kind):
    n = np.arange(14)
    v = 0.3 * 0.83**n
    for anchored in (True, False):
        c, c_err = scaling.fit_decay(n, v, 2, 12, kind, anchored)
        assert c == pytest.approx(0.83, rel=1e-10) and c_err < 1e-8


def test_a_free_start_ignores_an_outlying_start_bead_that_an_anchored_one_follows():
    n = np.arange(14)
    v = 0.3 * 0.83**n
    v[2] *= 1.3
    anchored, _ = scaling.fit_decay(n, v, 2, 12, anchored=True)
    free, _ = scaling.fit_decay(n, v, 2, 12, anchored=False)
    assert anchored < 0.83 - 0.01  # pulled down to bridge the raised V_2
    assert abs(free - 0.83) < abs(anchored - 0.83)


@pytest.mark.parametrize("name", ["30/30", "0/0"])
def test_every_protocol_recovers_an_exact_law(name):
    combination = scaling.COMBINATIONS[name]
    search = protocols.search_protocols(name, V0, synthetic_peaks(combination), EXACT, max_last=13)
    expected = (
        len(protocols.STARTS)
        * 2
        * 2
        * sum(30 - size + 1 for size in range(protocols.MIN_V0, 31))
        * np.mean([13 - s - 1 for s in protocols.STARTS])
    )
    assert len(search) == expected
    assert np.max(search.distance) < 1e-8 and search.consistent.all()
    stated = search.find(combination.start, 12, True, "loglinear", 0, 29)
    assert search.row(stated)[3:8] == (True, "loglinear", V0[0], V0[-1], 30)


def test_the_search_finds_the_protocols_an_outlier_does_not_touch():
    """Raise every V_1 by 20 %: protocols anchored at bead 1 lose the law, those starting
    at bead 2 or later (or free) keep it, and the closest protocol is one of those."""
    combination = scaling.COMBINATIONS["30/30"]
    peaks = synthetic_peaks(combination)
    peaks[:, 1] *= 1.2
    search = protocols.search_protocols("30/30", V0, peaks, EXACT, max_last=13)
    anchored_at_1 = search.anchored & (search.start == 1)
    assert search.distance[anchored_at_1].min() > 0.01
    assert search.distance[search.start >= 2].max() < 1e-8
    best = search.closest()[0]
    assert search.start[best] >= 2 or not search.anchored[best]
    assert search.consistent_shares()["start_1"] < 1 / 3  # the anchored start-1 protocols drop out
