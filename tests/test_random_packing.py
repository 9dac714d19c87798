"""A random polydisperse disc (shape = "random"): drawn reproducibly, packed by LAMMPS until every
bead rests on its neighbours, then struck, with both engines agreeing."""

import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from hexdem.cli.main import main
from hexdem.engines.lammps.settling import DECK_NAME
from hexdem.errors import HexdemError
from hexdem.experiments import random_packing
from hexdem.experiments.compare import run_comparison
from hexdem.experiments.random_packing import PACKING_NAME, prepare_random_packing
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.placed import MAX_REST_OVERLAP
from hexdem.model.random_disc import DENSE_FRACTION, LOOSE_GAP, edge_bead, loose_positions, random_diameters

D = RunConfig().diameter_m
#: Neighbours closer than this are touching at rest [m]: far below the µm overlaps of a 0.4 m/s impact.
TOUCHING_M = 1e-6
SMALL = {"shape": "random", "radius_m": 0.06, "seed": 1}


def gaps(positions, diameters):
    """(i, j, gap [m]) of the pairs of beads closer than two diameters."""
    i, j = cKDTree(positions).query_pairs(2 * diameters.max(), output_type="ndarray").T
    return i, j, np.linalg.norm(positions[i] - positions[j], axis=1) - (diameters[i] + diameters[j]) / 2


def test_the_diameters_are_seeded_spread_and_fill_the_disc():
    diameters = random_diameters(0.1, D, 0.15, 7)
    assert np.array_equal(diameters, random_diameters(0.1, D, 0.15, 7))
    assert not np.array_equal(diameters[:10], random_diameters(0.1, D, 0.15, 8)[:10])
    assert D * 0.85 <= diameters.min() and diameters.max() <= D * 1.15
    assert diameters.std() == pytest.approx(0.15 * D / math.sqrt(3), rel=0.2)  # uniform: half-width / √3
    area = np.sum(math.pi * diameters**2 / 4)
    assert DENSE_FRACTION * math.pi * 0.1**2 <= area < DENSE_FRACTION * math.pi * 0.1**2 + math.pi * (1.15 * D) ** 2 / 4


def test_the_loose_start_keeps_every_bead_apart():
    diameters = random_diameters(0.1, D, 0.15, 2)
    positions = loose_positions(diameters, 2)
    _, _, gap = gaps(positions, diameters)
    assert gap.min() >= LOOSE_GAP * 0.85 * D


def test_the_struck_bead_is_the_middle_of_the_edge_facing_the_strike():
    """On a 5 × 5 square grid, a strike along +x meets the middle of the left column first, one
    along +y the middle of the bottom row; a bead behind another is never chosen."""
    grid = np.array([(x, y) for x in range(5) for y in range(5)], float) * D
    diameters = np.full(len(grid), D)
    assert tuple(grid[edge_bead(grid, diameters, [1.0, 0.0])] / D) == (0, 2)
    assert tuple(grid[edge_bead(grid, diameters, [0.0, 1.0])] / D) == (2, 0)
    assert tuple(grid[edge_bead(grid, diameters, [-1.0, 0.0])] / D) == (4, 2)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"diameter_spread": 0.5}, "diameter_spread must be at least 0 and below 0.5"),
        ({"radius_m": 0.01}, "radius_m must be at least 1.5 diameter_m"),
        ({"radius_m": D}, r"radius_m must be at least 1.5 diameter_m = 0.028575 m for a random disc \(a middle bead "),
        ({"seed": -1}, "seed must be an integer >= 0"),
        ({"seed": 1.5}, "seed must be an integer"),
    ],
)
def test_bad_random_discs_are_one_line_errors(changes, message):
    with pytest.raises(HexdemError, match=message) as error:
        RunConfig(shape="random", **changes)
    assert "\n" not in str(error.value)


def test_the_smallest_random_disc_settles_with_a_bead_at_its_centre(tmp_path):
    """A disc of the smallest radius, 1.5 d (seed 0: 8 beads, one of them brought to the centre), is
    packed: the pull that flips across the centre shook its middle bead at about 1 mm/s for
    2,000,000 steps before the pull fell to zero within PULL_CORE_M of the centre. Its beads rest
    on each other, the middle one among them."""
    config = RunConfig(shape="random", radius_m=1.5 * D, seed=0)
    packed = prepare_random_packing(config, tmp_path)
    table = np.loadtxt(packed.packing_file, delimiter=",", skiprows=1, ndmin=2)
    positions, diameters = table[:, :2], table[:, 2]
    middle = np.argmin(np.linalg.norm(positions - positions.mean(axis=0), axis=1))
    i, j, gap = gaps(positions, diameters)
    touching = gap < TOUCHING_M
    assert len(diameters) == 8
    assert np.sum(touching & ((i == middle) | (j == middle))) >= 3  # held from every side, not only pressed


def test_a_random_disc_is_built_only_once_packed():
    with pytest.raises(HexdemError, match="packed by a LAMMPS compaction"):
        build_model(RunConfig(**SMALL))


@pytest.mark.parametrize("command", [["run"], ["compare"], ["sweep", "--vary", "v0=0.3,0.4"]])
def test_a_random_disc_that_cannot_run_is_refused_before_it_is_packed(tmp_path, capsys, command):
    """A sensor id beyond the disc's beads: refused on the loose start in one line, before LAMMPS
    packs it, by every command (compare once left the packing in --out; sweep checked nothing)."""
    (tmp_path / "random.toml").write_text('shape = "random"\nradius_m = 0.06\nseed = 1\nsensors = [100000]\n')
    out = tmp_path / "out"
    assert (
        main([*command, "--config", str(tmp_path / "random.toml"), "--out", str(out)]) == 3
    )  # refused before it is packed
    lines = [line for line in capsys.readouterr().err.strip().splitlines() if "error" in line]
    assert len(lines) == 1 and "sensor bead id 100000 is not in the packing" in lines[0], lines
    assert not out.exists() or not any(out.iterdir())


def test_a_stage_that_does_not_settle_is_kept_where_its_message_says(tmp_path, monkeypatch, capsys):
    stage = random_packing.settling_stage
    monkeypatch.setattr(random_packing, "settling_stage", lambda name: replace(stage(name), max_steps=1000))
    (tmp_path / "random.toml").write_text('shape = "random"\nradius_m = 0.06\nseed = 1\n')
    assert (
        main(["run", "--config", str(tmp_path / "random.toml"), "--out", str(tmp_path / "out")]) == 4
    )  # the run started and failed
    error = [line for line in capsys.readouterr().err.splitlines() if "error" in line][0]
    assert "compact stage did not settle in" in error
    assert (Path(error.rsplit("see ", 1)[1]) / DECK_NAME).is_file()
    assert not (tmp_path / "out").exists()


def test_a_settling_deck_that_lammps_refuses_is_kept_where_its_message_says(tmp_path, monkeypatch, capsys):
    """LAMMPS failing on a stage's deck (here made to by its runner) is the run's one-line failure,
    naming the deck where it was kept."""
    from hexdem.errors import RunFailed

    def refuse(deck):
        raise RunFailed(f"LAMMPS failed on {deck / DECK_NAME}: ERROR: Lost atoms")

    monkeypatch.setattr(random_packing, "run_settling_deck", refuse)
    (tmp_path / "random.toml").write_text('shape = "random"\nradius_m = 0.06\nseed = 1\n')
    assert main(["run", "--config", str(tmp_path / "random.toml"), "--out", str(tmp_path / "out")]) == 4
    error = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert len(error) == 1 and "ERROR: Lost atoms" in error[0] and "Traceback" not in error[0], error
    kept = Path(error[0].split("LAMMPS failed on ", 1)[1].split(":", 1)[0])
    assert kept.is_file() and "hexdem-failed-" in str(kept)
    assert not (tmp_path / "out").exists()


@pytest.fixture(scope="module")
def compared(tmp_path_factory):
    out = tmp_path_factory.mktemp("random")
    return out, run_comparison(RunConfig(**SMALL), out, log=lambda message: None)


def test_the_packed_disc_rests_bead_on_bead(compared):
    """Pulled to its centre and released, every bead ends at rest on at least two neighbours (one
    contact cannot hold a bead against the pull), none overlapping more than a rest overlap;
    the beads with three contacts or more are jammed, with about the isostatic four each
    (2 per bead in 2D, frictionless)."""
    out, _ = compared
    packing = np.loadtxt(out / "preparation" / PACKING_NAME, delimiter=",", skiprows=1)
    positions, diameters = packing[:, :2], packing[:, 2]
    i, j, gap = gaps(positions, diameters)
    assert -gap.min() < MAX_REST_OVERLAP * diameters.min()
    touching = gap < TOUCHING_M
    contacts = np.bincount(np.r_[i[touching], j[touching]], minlength=len(diameters))
    assert contacts.min() >= 2
    assert 3.8 < contacts[contacts >= 3].mean() < 5.0


def test_the_same_seed_packs_the_same_disc_and_says_so_stage_by_stage(compared, tmp_path):
    out, _ = compared
    messages = []
    again = prepare_random_packing(RunConfig(**SMALL), tmp_path, log=messages.append)
    assert (tmp_path / PACKING_NAME).read_bytes() == (out / "preparation" / PACKING_NAME).read_bytes()
    assert again.shape == "packing" and again.struck_bead >= 0
    stages = [
        found.group(2) for message in messages if (found := re.match(r"random disc(, stage \d of 2:|,) (\w+)", message))
    ]
    assert stages == ["compact", "compact", "relax", "relax"] and messages[-1].startswith("random disc packed")
    assert all(
        re.search(r"settled after \d+ steps, [\d.e+-]+ s simulated, in [\d.]+ s$", message)
        for message in messages[2:-1:2]
    )


def test_both_engines_agree_on_a_struck_random_disc(compared):
    _, comparison = compared
    assert comparison.agree, comparison.verdict()
    assert comparison.n_checked >= 8


def test_each_engines_run_of_a_compared_random_disc_names_it(compared):
    """Both engines strike the one packing, and their runs' titles and summaries name it as a direct
    run's do (they said 'packing of packing.csv')."""
    import json

    out, _ = compared
    for engine in ("lammps", "reference"):
        summary = json.loads((out / engine / "summary.json").read_text())
        assert summary["lattice"]["shape"] == f"random disc of {summary['lattice']['n_beads']} beads (seed 1)"
        assert summary["config"]["shape"] == "random" and summary["engine"] == engine


def test_a_random_discs_summary_says_what_it_is_and_lists_its_own_keys(tmp_path):
    """Its titles and summary name a random disc of N beads (they said 'packing of packing.csv'),
    and summary.json's config holds the keys of a random disc, not a hexagon's edge_beads."""
    import json

    (tmp_path / "random.toml").write_text('shape = "random"\nradius_m = 0.06\nseed = 1\n')
    assert main(["run", "--config", str(tmp_path / "random.toml"), "--out", str(tmp_path / "out")]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["lattice"]["shape"] == f"random disc of {summary['lattice']['n_beads']} beads (seed 1)"
    assert {"radius_m", "seed", "walls", "v0"} <= set(summary["config"])
    assert not {"edge_beads", "rows", "beads", "struck_bead", "packing_file"} & set(summary["config"])
