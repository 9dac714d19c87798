"""Wavefront snapshots (hexdem.experiments.snapshots, Figs. 3 and 4) on real LAMMPS, one and two ranks."""

import json

import numpy as np
import pytest
from conftest import read_csv
from readable import saved_figure, smallest_text_px

from hexdem.cli.main import main
from hexdem.errors import HexdemError
from hexdem.experiments.snapshots import Snapshots, snapshot_config, snapshot_figure, take_snapshots
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.run_settings import run_settings
from hexdem.model.triangular import hexagon

TIMES_S = (1e-4, 2e-4, 3e-4)
#: A half-hexagon small enough for seconds, large enough to split between two ranks.
SMALL_HALF = RunConfig(shape="half-hexagon", long_edge=21, short_edge=11, impact="striker", v0=0.4)


@pytest.mark.parametrize("times_ms", [(0.15, 0.3, 0.45, 0.6), (0.25, 1.0), (0.123, 0.5)])
def test_frames_fall_exactly_on_the_requested_times(times_ms):
    config = RunConfig(impact="striker")
    model = build_model(config)
    snap = snapshot_config(config, model, [t * 1e-3 for t in times_ms])
    settings = run_settings(snap, model)
    assert settings.dt_s <= run_settings(config, model).dt_s
    interval = settings.dt_s * settings.dump_every
    for t in times_ms:
        assert t * 1e-3 / interval == pytest.approx(round(t * 1e-3 / interval), abs=1e-9)
    assert settings.n_steps * settings.dt_s == pytest.approx(max(times_ms) * 1e-3, rel=1e-12)


@pytest.mark.parametrize("times", [(), (2e-4, 2e-4), (0.0, 1e-4), (-1e-4,)])
def test_bad_times_are_refused(times):
    with pytest.raises(HexdemError, match="snapshot times must be distinct and at least 1 µs"):
        snapshot_config(RunConfig(impact="striker"), None, times)


@pytest.fixture(scope="module")
def one_and_two_ranks(tmp_path_factory):
    base = tmp_path_factory.mktemp("snapshots")
    model = build_model(SMALL_HALF)
    return [take_snapshots(SMALL_HALF.replace(ranks=ranks), model, TIMES_S, base / f"ranks{ranks}") for ranks in (1, 2)]


def test_one_and_two_ranks_give_the_same_speeds(one_and_two_ranks):
    one, two = one_and_two_ranks
    assert (one.engine["ranks"], two.engine["ranks"]) == (1, 2)
    np.testing.assert_allclose(one.times_s, TIMES_S, rtol=1e-12)
    np.testing.assert_allclose(two.speeds, one.speeds, rtol=1e-9, atol=1e-12 * one.speeds.max())


def test_the_front_moves_outward_and_nothing_moves_ahead_of_it(one_and_two_ranks):
    """Uncompressed Hertz beads feel nothing before the wave reaches them: at each time the
    moving beads lie within a distance of the struck bead that grows with time, and beyond it
    every bead is at rest (below 1e-9 V0: the walls touch their beads to round-off, whose
    forces of ~1e-16 N move beads at ~1e-18 m/s)."""
    snapshots = one_and_two_ranks[0]
    lattice = snapshots.packing
    distance = np.linalg.norm(lattice.positions_m - lattice.positions_m[lattice.struck], axis=1)
    moving = snapshots.speeds > 1e-9 * SMALL_HALF.v0
    reach = np.array([distance[m].max() for m in moving])
    assert np.all(np.diff(reach) > lattice.diameter_m)
    assert reach[0] < distance.max() and np.count_nonzero(~moving[0]) > len(lattice) / 2


def test_the_command_writes_the_figure_and_its_table(tmp_path):
    out = tmp_path / "fig3"
    assert main(["snapshots", "--out", str(out), "--edge-beads", "5", "--times", "0.1,0.2", "--outline-edge", "3"]) == 0
    _, rows = read_csv(out / "fig3_smallsim.csv")
    assert len(rows) == 2 * 61
    assert sorted({float(row["time"]) for row in rows}) == pytest.approx([1e-4, 2e-4], rel=1e-12)
    assert (out / "fig3_smallsim.png").stat().st_size > 0
    summary = json.loads((out / "snapshots.json").read_text())
    assert summary["ranks"] == 1 and summary["n_beads"] == 61


@pytest.mark.parametrize(
    "config", [RunConfig(edge_beads=11), RunConfig(shape="half-hexagon", long_edge=41, short_edge=21)]
)
def test_the_panels_share_one_colour_bar_readable_in_the_report(monkeypatch, config):
    """Six panels, one colour scale from 0 to the median of their largest speeds with one bar
    (Fig. 4 had six bars of 6-point labels), every text at least 10 px where the report shows it."""
    lattice = build_packing(config)
    speeds = np.random.default_rng(1).uniform(0.0, 0.05, (6, len(lattice))) * np.arange(1, 7)[:, None]
    snapshots = Snapshots(config, lattice, np.arange(1, 7) * 2e-4, speeds, {})
    fig = saved_figure(
        monkeypatch,
        lambda: snapshot_figure(snapshots, build_model(config).walls, "unused.png", hexagon(11, config.diameter_m)),
    )
    panels = [ax for ax in fig.axes if ax.get_title().startswith("t = ")]
    assert len(panels) == 6 and len(fig.axes) == 7, "six panels and one colour bar"
    assert all(ax.collections[0].get_clim() == (0.0, np.median(speeds.max(axis=1))) for ax in panels)
    assert smallest_text_px(fig) >= 10


def test_bad_times_on_the_command_line_are_one_clear_line(tmp_path, capsys):
    assert main(["snapshots", "--out", str(tmp_path / "x"), "--times", "0.1;0.2"]) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == ["hexdem: error: --times must be comma-separated numbers in ms, e.g. 0.2,0.4,0.6; got '0.1;0.2'"]
