"""Any initial state (``initial_state_file``): two spheres set against each other by it, in both
engines, against momentum and energy conservation worked out by hand; the time step set by the
state's fastest approach, a state too fast for Hertz contacts refused; the state copied into
the deck; bad files refused in one line before anything is written."""

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import contact_of, read_csv, settings_of

from hexdem.cli.main import main
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.model.materials import hertz_coefficient, sphere_mass
from hexdem.model.model_builder import build_model, build_packing

#: Two touching spheres on the +30° line, no walls, the first struck along the line.
PAIR = {"shape": "sites", "sites": [[0, 0], [1, 1]], "site_walls_deg": [], "strike_angle_deg": 30.0}
ALONG = np.array([math.cos(math.radians(30.0)), math.sin(math.radians(30.0))])


def final_speeds(config, directory):
    """The two beads' speeds at the run's last sample."""
    analysis = simulate(config, directory, trace_lines=["+30"])
    return analysis.line_trace("+30")[1][-1]


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_a_head_on_collision_set_up_by_the_initial_state_exchanges_the_velocities(engine, tmp_path):
    """Bead 0 struck at 0.4 m/s towards bead 1, which the file sets moving at 0.2 m/s towards
    it: equal masses meeting head on, elastically, swap their velocities."""
    state = tmp_path / "state.csv"
    vx, vy = (float(v) for v in -0.2 * ALONG)
    state.write_text(f"m,n,vx,vy\n1,1,{vx!r},{vy!r}\n")
    config = RunConfig(**PAIR, v0=0.4, duration=4e-4, engine=engine, initial_state_file=str(state))
    np.testing.assert_allclose(final_speeds(config, tmp_path / "run"), [0.2, 0.4], rtol=1e-6)


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_an_overlap_set_up_by_the_displacements_pushes_the_spheres_apart(engine, tmp_path):
    """Bead 1 displaced by δ = 2 µm into bead 0 (which its impact moves at V0 = 1 µm/s): the
    Hertz energy (2/5) A δ^(5/2) turns into motion. With momentum m V0 and energy
    E = (2/5) A δ^(5/2) + m V0²/2, the final velocities along the line u0 + u1 = V0 and
    u0² + u1² = 2E/m give u1 − u0 = sqrt(4E/m − V0²)."""
    d, delta, v0 = 0.01905, 2e-6, 1e-6
    state = tmp_path / "state.csv"
    dx, dy = (float(v) for v in -delta * ALONG)
    state.write_text(f"m,n,vx,vy,dx,dy\n1,1,0,0,{dx!r},{dy!r}\n")
    config = RunConfig(
        **PAIR, v0=v0, dt=2e-7, duration=4e-4, dump_every=20, engine=engine, initial_state_file=str(state)
    )
    mass, energy = (
        float(sphere_mass(d)),
        0.4 * float(hertz_coefficient(d)) * delta**2.5 + 0.5 * float(sphere_mass(d)) * v0**2,
    )
    expected = math.sqrt(4 * energy / mass - v0**2)
    first, second = final_speeds(config, tmp_path / "run")
    assert first + second == pytest.approx(expected, rel=1e-4)  # u0 < 0: they fly apart
    assert second - first == pytest.approx(v0, abs=1e-4 * expected)  # the momentum, m V0


@pytest.mark.parametrize(
    "text, message",
    [
        ("m,n,vx\n", "the header must be m,n,vx,vy or m,n,vx,vy,dx,dy"),
        ("m,n,vx,vy\n1,1,fast,0\n", "line 2: m and n must be integers and the rest numbers"),
        ("m,n,vx,vy\n1,1,nan,0\n", "line 2: the values must be finite numbers"),
        ("m,n,vx,vy\n5,5,0.1,0\n", "line 2: site {5, 5} is not a bead of the packing"),
        ("m,n,vx,vy\n1,1,0.1,0\n1,1,0.2,0\n", "line 3: site {1, 1} is listed twice"),
        ("m,n,vx,vy,dx,dy\n1,1,0,0,0.01,0\n", "a displacement of half a diameter or more"),
        ("m,n,vx,vy\n1,1,0.1\n", "line 2: 3 values, the header has 4"),
    ],
)
def test_bad_initial_state_files_are_one_line_and_write_nothing(tmp_path, capsys, text, message):
    (tmp_path / "state.csv").write_text(text)
    (tmp_path / "run.toml").write_text(
        'shape = "sites"\nsites = [[0, 0], [1, 1]]\nsite_walls_deg = []\n'
        f'initial_state_file = "{tmp_path / "state.csv"}"\n'
    )
    assert main(["run", "--config", str(tmp_path / "run.toml"), "--out", str(tmp_path / "out")]) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_the_time_step_follows_the_fastest_bead_of_the_state(tmp_path):
    """The step resolves the shortest contact, t_c ∝ V^(-1/5) at the fastest approach V. A bead
    of the struck edge given 100 m/s (250 V0) into the packing approaches its neighbours and the
    walls at 100 m/s, so the step is 250^(1/5) = 3.02 times shorter than at V0; the run lasts as
    long, the time the impact's pulse needs to cross the packing. With as many steps per contact as
    the default experiment, LAMMPS keeps the energy as well as there (drift 4.8e-5; 4.2e-4 at the
    step of V0, which scales as dt²)."""
    (tmp_path / "state.csv").write_text("m,n,vx,vy\n4,0,100.0,0\n")
    base = RunConfig(edge_beads=5)
    fast = base.replace(initial_state_file=str(tmp_path / "state.csv"))
    assert settings_of(base).dt_s / settings_of(fast).dt_s == pytest.approx(250**0.2, rel=1e-12)
    assert settings_of(fast).duration_s == pytest.approx(settings_of(base).duration_s, abs=settings_of(base).dt_s)
    assert simulate(fast, tmp_path / "run").results.energy_drift < 1e-4


def test_the_fastest_approach_is_that_of_two_beads_meeting(tmp_path):
    """Bead 1 of the pair set at 0.2 m/s towards bead 0, struck at 0.4: they close at 0.6 m/s,
    the contact is (0.6/0.4)^(-1/5) of the impact's alone. A free pair has no wall at rest to
    measure against."""
    state = tmp_path / "state.csv"
    vx, vy = (float(v) for v in -0.2 * ALONG)
    state.write_text(f"m,n,vx,vy\n1,1,{vx!r},{vy!r}\n")
    alone = contact_of(RunConfig(**PAIR))
    assert contact_of(RunConfig(**PAIR, initial_state_file=str(state))) == pytest.approx(alone * 1.5**-0.2, rel=1e-12)


def test_a_state_too_fast_for_hertz_contacts_is_refused_in_one_line(tmp_path, capsys):
    """A bead given 1e6 m/s would press 67 diameters into its neighbour: Hertz's law, and the
    packing, end at half a diameter."""
    (tmp_path / "state.csv").write_text("m,n,vx,vy\n4,0,1e6,0\n")
    (tmp_path / "run.toml").write_text(f'edge_beads = 5\ninitial_state_file = "{tmp_path / "state.csv"}"\n')
    assert main(["run", "--config", str(tmp_path / "run.toml"), "--out", str(tmp_path / "out")]) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert (
        len(lines) == 1
        and "at 1e+06 m/s, two steel316 beads meeting head on would overlap by 67.2 diameters" in lines[0]
    ), lines
    assert not (tmp_path / "out").exists()


def test_a_deck_with_a_relative_initial_state_is_analysed_from_inside(tmp_path, monkeypatch):
    """The run copies the state into its deck, so ``hexdem analyse .`` inside the deck (the
    state's relative path no longer leads to it) reads the same packing and finds the run's own
    peaks (as the analysis of a dump does, test_streaming.py)."""
    monkeypatch.chdir(tmp_path)
    Path("state.csv").write_text("m,n,vx,vy\n1,1,0.1,0.05\n")
    Path("run.toml").write_text('edge_beads = 4\nduration = 1e-3\ninitial_state_file = "state.csv"\n')
    assert main(["run", "--config", "run.toml", "--out", "out", "--dump"]) == 0
    monkeypatch.chdir(tmp_path / "out" / "deck")
    assert Path("initial_state_file.csv").read_text() == (tmp_path / "state.csv").read_text()
    assert main(["analyse", ".", "--out", str(tmp_path / "analysed")]) == 0
    _, ran = read_csv(tmp_path / "out" / "peaks.csv")
    _, analysed = read_csv(tmp_path / "analysed" / "peaks.csv")
    np.testing.assert_allclose(
        [float(row["peak_speed"]) for row in analysed], [float(row["peak_speed"]) for row in ran], rtol=1e-4
    )


def test_a_missing_initial_state_file_is_one_line(tmp_path):
    with pytest.raises(Exception, match="cannot read initial_state_file"):
        build_model(RunConfig(**PAIR, initial_state_file=str(tmp_path / "nowhere.csv")))


def test_both_engines_agree_on_a_random_initial_state_in_a_precompressed_packing(tmp_path):
    """A hexagon of 5 per edge under 20 N, every bead given a random velocity (0.1 mm/s) and
    displacement (10 nm, seeded) besides a weak impact. The reference integrator (RK4) is exact
    here to far below LAMMPS's velocity Verlet, whose error is second order in the step: LAMMPS
    at 140 and 280 steps per contact differs from it by 1e-3 of the largest peak or less, and
    four times less at the finer step (3 to 5: second order)."""
    rng = np.random.default_rng(7)
    config = RunConfig(edge_beads=5, precompression_n=20.0, v0=1e-4)
    velocities, displacements = 1e-4 * rng.standard_normal((61, 2)), 1e-8 * rng.standard_normal((61, 2))
    lines = ["m,n,vx,vy,dx,dy"] + [
        f"{m},{n}," + ",".join(repr(float(v)) for v in (*u, *d))
        for (m, n), u, d in zip(build_packing(config).labels.tolist(), velocities, displacements)
    ]
    (tmp_path / "state.csv").write_text("\n".join(lines) + "\n")
    config = config.replace(initial_state_file=str(tmp_path / "state.csv"), duration=5e-4)
    reference = simulate(config.replace(engine="reference", steps_per_contact=280), tmp_path / "reference").results
    scale = np.nanmax(reference.peak_speed)
    errors = []
    for steps in (140, 280):
        lammps = simulate(config.replace(steps_per_contact=steps), tmp_path / f"lammps{steps}").results
        assert np.array_equal(np.isnan(lammps.peak_speed), np.isnan(reference.peak_speed))
        errors.append(np.nanmax(np.abs(lammps.peak_speed - reference.peak_speed)) / scale)
    assert errors[0] < 1e-3 and 3 < errors[0] / errors[1] < 5, errors


def test_beads_csv_places_the_beads_where_the_state_starts_them(tmp_path):
    """A displacement of the state moves the bead's x, y in beads.csv: the table shows where the
    beads are at t = 0, not the packed sites."""
    state = tmp_path / "state.csv"
    state.write_text("m,n,vx,vy,dx,dy\n1,1,0,0,0.001,-0.002\n")
    config = tmp_path / "run.toml"
    config.write_text(
        'shape = "sites"\nsites = [[0, 0], [1, 1], [0, 4]]\nsite_walls_deg = []\nduration = 2e-4\n'
        f'initial_state_file = "{state}"\n'
    )
    assert main(["run", "--config", str(config), "--out", str(tmp_path / "out")]) == 0
    packed = build_packing(RunConfig(shape="sites", sites=[[0, 0], [1, 1], [0, 4]])).positions_m
    rows = read_csv(tmp_path / "out" / "beads.csv")[1]
    placed = np.array([[float(row["x"]), float(row["y"])] for row in rows])
    np.testing.assert_allclose(placed - packed, [[0, 0], [0.001, -0.002], [0, 0]], atol=1e-15)
