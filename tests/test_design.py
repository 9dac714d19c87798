"""``hexdem design``: the criterion against its closed form, a small design study end to end, and
bad input refused in one line before anything is written."""

import csv
import json

import numpy as np
import pytest

from hexdem.calibration.priors import Prior
from hexdem.cli.main import main
from hexdem.design.criterion import Z90, Moments
from hexdem.design.search import search

SMALL = "edge_beads = 5\n"
COLUMNS = ["rank", "sensors", "v_striker", "criterion", "width_v0"]
#: 2 sensors among the lines' beads, V0 ~ uniform(0.2, 0.7), 4 records, 8 simulations.
SMALL_DESIGN = ["--prior", "v0=uniform(0.2, 0.7)", "--sensors", "2", "--candidates", "lines", "--noise", "5"]
SMALL_DESIGN += ["--records", "4", "--budget", "8"]


def one_key_moments(slopes, noise_var, points: int = 5) -> Moments:
    """Beads whose log peak is exactly linear in the one standardised key z with ``slopes``, whose
    arrivals do not move, each log peak of noise variance ``noise_var``."""
    n = len(slopes)
    z = np.linspace(-1.5, 1.5, points)
    mean = np.zeros((points, n, 2))
    mean[:, :, 0] = z[:, None] * np.asarray(slopes)
    mean[:, :, 1] = 100.0 * (1 + np.arange(n))
    slope = np.zeros((points, n, 2, 1))
    slope[:, :, 0, 0] = slopes
    noise = np.zeros((points, n, 3))
    noise[:, :, 0], noise[:, :, 1] = noise_var, 1.0
    return Moments(mean, slope, noise, np.zeros((points, 1, n, 2)), np.ones(points), np.array([2.0]), np.array([10.0]))


def test_the_posterior_of_one_linear_observable_is_the_closed_form():
    """One sensor whose log peak is b z + noise of variance s², R records, no gain: the posterior
    variance of z is 1 / (1 + R b² / s²); with a gain of sd g common to the records it is
    1 / (1 + b² / (s²/R + g²)): more records cannot beat the gain."""
    b, s2 = 0.3, 0.01
    moments = one_key_moments([b], s2)
    for records in (1, 4, 20):
        posterior = moments.posterior([0], records, 0.0, 0.0)
        np.testing.assert_allclose(posterior[:, 0, 0], 1 / (1 + records * b**2 / s2), rtol=1e-6)
        gained = moments.posterior([0], records, 0.05, 0.0)
        np.testing.assert_allclose(gained[:, 0, 0], 1 / (1 + b**2 / (s2 / records + 0.05**2)), rtol=1e-6)
    gain, widths = moments.score([0], 20, 0.0, 0.0)
    variance = 1 / (1 + 20 * b**2 / s2)
    assert gain == pytest.approx(-0.5 * np.log(variance), rel=1e-6)
    assert widths[0] == pytest.approx(2 * Z90 * np.sqrt(variance) * 2.0, rel=1e-6)


def test_the_search_finds_the_beads_that_move_most():
    """Of beads whose log peaks depend on the key with slopes 0.1 to 0.6 (equal noise), the best
    pair is the two steepest, exhaustively and by greedy exchange alike."""
    slopes = [0.1, 0.6, 0.2, 0.5, 0.3, 0.15]
    moments = one_key_moments(slopes, 0.01)

    def score(design):
        return moments.score(list(design), 1, 0.0, 0.0)[0]

    method, scored = search(score, len(slopes), 2)
    assert method == "exhaustive" and max(scored, key=scored.get) == (1, 3)
    many = one_key_moments(np.linspace(0.01, 0.5, 300), 0.01)
    method, scored = search(lambda d: many.score(list(d), 1, 0.0, 0.0)[0], 300, 3)
    assert method == "greedy and exchange" and max(scored, key=scored.get) == (297, 298, 299)


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    """A design of 2 sensors among the lines' beads of the 5-per-edge hexagon, V0 ~ uniform(0.2, 0.7)."""
    root = tmp_path_factory.mktemp("design")
    (root / "base.toml").write_text(SMALL)
    out = root / "out"
    code = main(["design", "--config", str(root / "base.toml"), *SMALL_DESIGN, "--out", str(out)])
    assert code == 0
    return out


@pytest.mark.xdist_group("design")
def test_a_design_writes_its_ranked_table_summary_and_figure(designed):
    with open(designed / "design.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == COLUMNS
    criteria = [float(row[3]) for row in rows[1:]]
    assert [int(row[0]) for row in rows[1:]] == list(range(1, len(rows)))
    assert criteria == sorted(criteria, reverse=True) and len(rows) - 1 == min(20, len(rows) - 1)
    assert all(len(row[1].split()) == 2 and float(row[2]) > 0 for row in rows[1:])
    summary = json.loads((designed / "design.json").read_text())
    assert summary["simulations"]["runs"] == 8 and summary["best"]["sensors"] == rows[1][1]
    assert "paper_configurations" not in summary, "the 5-per-edge hexagon is not the paper's lattice"
    prior_width = 0.9 * 0.5
    assert 0 < summary["best"]["width_v0"] < prior_width
    assert (designed / "design.png").stat().st_size > 10_000


@pytest.mark.xdist_group("design")
def test_a_design_run_again_resumes_from_its_simulations(designed, capsys):
    stamps = {p: p.stat().st_mtime_ns for p in (designed / "simulations").glob("*/moments.npz")}
    code = main(["design", "--config", str(designed.parent / "base.toml"), *SMALL_DESIGN, "--out", str(designed)])
    assert code == 0 and len(stamps) == 8
    assert {p: p.stat().st_mtime_ns for p in (designed / "simulations").glob("*/moments.npz")} == stamps


BAD_INPUT = [
    (["--sensors", "80", "--candidates", "lines"], "--sensors 80: there are only"),
    (["--sensors", "2", "--candidates", "0:1,0:99"], "line 0 has beads 0 to"),
    (["--sensors", "2", "--candidates", "0:0,0:2"], "is the struck bead"),
    (
        ["--sensors", "2", "--prior", "restitution=uniform(0.8, 0.99)", "--speeds", "0.4,-0.2"],
        "distinct striker speeds > 0",
    ),
    (
        ["--sensors", "2", "--prior", "restitution=uniform(0.8, 0.99)", "--speeds", "0.4,0"],
        "distinct striker speeds > 0",
    ),
    (["--sensors", "2", "--speeds", "0.3,0.4"], "--speeds: v0 has a prior"),
    (["--sensors", "2", "--prior", "restitution=uniform(0.8, 1.2)"], "--prior"),
    (["--sensors", "2", "--noise", "0"], "--noise 0.0: the accelerometers' noise"),
]


@pytest.mark.parametrize("options, message", BAD_INPUT)
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, capsys, options, message):
    (tmp_path / "base.toml").write_text(SMALL)
    out = tmp_path / "out"
    prior = [] if "--prior" in options else ["--prior", "v0=uniform(0.2, 0.7)"]
    noise = [] if "--noise" in options else ["--noise", "5"]
    code = main(["design", "--config", str(tmp_path / "base.toml"), *prior, *noise, "--out", str(out), *options])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 3 and len(err) == 1 and message in err[0], err
    assert not out.exists()


def test_the_criterion_prior_moments_are_the_priors():
    """A uniform prior's standard deviation is its width over √12 and its 90 % width 0.9 of it."""
    from hexdem.design.criterion import prior_moments

    mean, sd, width = prior_moments(Prior.parse("v0=uniform(0.2, 0.7)"))
    assert mean == pytest.approx(0.45, rel=1e-6)
    assert sd == pytest.approx(0.5 / np.sqrt(12), rel=1e-5)
    assert width == pytest.approx(0.45, rel=1e-6)
