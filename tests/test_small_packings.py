"""The smallest packings run from the CLI end to end: one bead against a wall, two beads colliding
obliquely, a chain. What cannot be measured on them is skipped with its reason, everything else
is written, and the final velocities read as the collision laws say."""

import json

import numpy as np
import pytest

from hexdem.cli.main import main
from hexdem.model.config import RunConfig
from hexdem.model.materials import PAPER_DIAMETER_M, material
from hexdem.model.timescale import pair_contact_time_s
from tests.conftest import read_csv

V0 = 0.4
#: The contact line of sites {0, 0} and {1, 1}: 30° from the strike along +x.
CONTACT_DEG = 30.0


def run_cli(tmp_path, config_text: str, engine: str) -> tuple[dict, list[dict]]:
    (tmp_path / "run.toml").write_text(config_text)
    out = tmp_path / engine
    assert main(["run", "--config", str(tmp_path / "run.toml"), "--out", str(out), "--engine", engine]) == 0
    return json.loads((out / "summary.json").read_text()), read_csv(out / "beads.csv")[1]


def end_velocities(beads: list[dict]) -> np.ndarray:
    return np.array([[float(bead["vx_end"]), float(bead["vy_end"])] for bead in beads])


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_single_bead_rebounds_from_a_wall_elastically(tmp_path, engine):
    """Head-on on a rigidly held elastic wall, with no dissipation, the bead leaves at −V0; the
    default duration holds the whole wall contact (steel on delrin: 323 µs at 0.4 m/s)."""
    summary, beads = run_cli(tmp_path, 'shape = "sites"\nsites = [[0, 0]]\nsite_walls_deg = [180]\n', engine)
    assert summary["lattice"]["n_beads"] == 1
    assert summary["duration"] > 323e-6
    np.testing.assert_allclose(end_velocities(beads)[0], [-V0, 0.0], atol=1e-7)
    assert set(summary["skipped_outputs"]) == {"front_shape.csv", "front_shape.png", "peak_decay.png"}
    assert all(reason for reason in summary["skipped_outputs"].values())
    assert not (tmp_path / engine / "front_shape.csv").exists()
    assert (tmp_path / engine / "peak_map.png").exists()


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_two_bead_oblique_collision_exchanges_the_normal_velocity(tmp_path, engine):
    """Equal frictionless elastic spheres exchange the velocity component along the line of
    centres n̂ and keep the rest: bead 2 leaves with (V0·n̂) n̂, bead 1 with V0 − (V0·n̂) n̂. The line
    of centres turns while they touch, by about the tangential slip over d, v_t τ / d (8e-4 rad
    here), which bounds the difference; momentum and kinetic energy are conserved exactly."""
    summary, beads = run_cli(
        tmp_path, 'shape = "sites"\nsites = [[0, 0], [1, 1]]\nsite_walls_deg = []\nduration = 3e-4\n', engine
    )
    normal = np.array([np.cos(np.radians(CONTACT_DEG)), np.sin(np.radians(CONTACT_DEG))])
    struck = np.array([V0, 0.0])
    expected = np.array([struck - (struck @ normal) * normal, (struck @ normal) * normal])
    steel, d = material("steel316"), PAPER_DIAMETER_M
    turn = V0 * np.sin(np.radians(CONTACT_DEG)) * pair_contact_time_s(steel, d, steel, d, struck @ normal) / d
    velocity = end_velocities(beads)
    np.testing.assert_allclose(velocity, expected, atol=V0 * turn)
    np.testing.assert_allclose(velocity.sum(axis=0), struck, atol=1e-12)
    assert np.sum(velocity**2) == pytest.approx(V0**2, rel=1e-6)
    assert "front_shape.csv" in summary["skipped_outputs"] and "peak_decay.png" not in summary["skipped_outputs"]


def test_two_bead_frictional_collision_conserves_momentum(tmp_path):
    """The issue's case (μ = 0.05): the run completes, momentum is conserved, and friction turns
    both spheres equally (the tangential force acts on both at the same lever arm)."""
    summary, beads = run_cli(
        tmp_path,
        'shape = "sites"\nsites = [[0, 0], [1, 1]]\nsite_walls_deg = []\nfriction = 0.05\nduration = 3e-4\n',
        "lammps",
    )
    np.testing.assert_allclose(end_velocities(beads).sum(axis=0), [V0, 0.0], atol=1e-9)
    spins = [float(bead["peak_angular_speed"]) for bead in beads]
    assert spins[0] > 0 and spins[0] == pytest.approx(spins[1], rel=1e-9)
    assert summary["energy_lost"] >= 0


def test_chain_along_a_contact_row_runs_and_skips_the_front(tmp_path):
    """Ten beads along +30°, struck along the row: the +30° line carries the pulse, the front
    (a 2D measurement) is skipped with its reason, and the run exits 0."""
    sites = ", ".join(f"[{k}, {k}]" for k in range(10))
    summary, beads = run_cli(tmp_path, f'shape = "sites"\nsites = [{sites}]\nstrike_angle_deg = 30\n', "lammps")
    assert "one line" in summary["skipped_outputs"]["front_shape.csv"]
    peaks = read_csv(tmp_path / "lammps" / "peaks.csv")[1]
    row = [float(p["peak_speed"]) for p in peaks if p["line"] == "+30"]
    assert len(row) == 10 and all(np.isfinite(row[:8]))
    velocity = end_velocities(beads)
    np.testing.assert_allclose(
        velocity.sum(axis=0), V0 * np.array([np.cos(np.radians(30)), np.sin(np.radians(30))]), atol=1e-9
    )


def test_a_bead_that_never_moved_has_peak_speed_zero(tmp_path):
    """A bead the pulse never reaches (apart from the struck one by a gap) peaks at exactly 0,
    with no time of peak or arrival; the struck bead keeps its V0."""
    from hexdem.experiments.run import simulate

    config = RunConfig(shape="sites", sites=[[0, 0], [0, 4]], site_walls_deg=[], duration=2e-4)
    r = simulate(config, tmp_path / "deck").results
    assert r.peak_speed[1] == 0.0 and np.isnan(r.arrival_time[1]) and np.isnan(r.t_peak[1])
    assert r.peak_speed[0] == pytest.approx(V0, rel=1e-12)


def test_a_rerun_replaces_the_results_and_keeps_the_users_files(tmp_path):
    """Results move into --out only once complete: a second run replaces the first's files and
    deck, leaves the user's own files, and no staging folder stays behind."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    for v0 in (0.4, 0.2):
        (tmp_path / "run.toml").write_text(f'shape = "sites"\nsites = [[0, 0]]\nsite_walls_deg = [180]\nv0 = {v0}\n')
        assert main(["run", "--config", str(tmp_path / "run.toml"), "--out", str(out)]) == 0
    assert float(read_csv(out / "beads.csv")[1][0]["vx_end"]) == pytest.approx(-0.2, rel=1e-6)
    assert json.loads((out / "deck" / "hexdem.json").read_text())["v0"] == 0.2
    assert (out / "notes.txt").read_text() == "mine"
    assert not [entry.name for entry in out.iterdir() if entry.name.startswith(".")]
