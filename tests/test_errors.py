"""Bad input gets one clear line from the CLI, exit status 3 (a failed run 4), and no partial result files."""

import dataclasses
import functools
import json
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import settings_of

from hexdem.analysis.dump import read_dump
from hexdem.cli.main import main
from hexdem.common.checks import positive_int
from hexdem.common.job_failure import reported_error
from hexdem.engines.lammps import deck, library
from hexdem.engines.lammps.deck import write_deck
from hexdem.engines.lammps.driver import run_streaming
from hexdem.engines.lammps.runner import run_bare
from hexdem.errors import HexdemError, RunFailed
from hexdem.experiments.parallel import run_on_ranks
from hexdem.experiments.run import run_experiment
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model


def run_cli(tmp_path, capsys, config_text=None, out=None):
    args = ["run", "--out", str(out or tmp_path / "out")]
    if config_text is not None:
        (tmp_path / "bad.toml").write_text(config_text)
        args += ["--config", str(tmp_path / "bad.toml")]
    code = main(args)
    lines = capsys.readouterr().err.strip().splitlines()
    assert not any("Traceback" in line for line in lines)
    progress = [line for line in lines if line.startswith("hexdem: ") and not line.startswith("hexdem: error:")]
    return code, [line for line in lines if line not in progress]


def assert_no_results(directory):
    """A failed run leaves nothing in its --out: not a result, not a deck, not a hidden folder."""
    assert not directory.exists() or not any(directory.iterdir())


def kept_deck(message: str) -> Path:
    """The folder outside --out where a failed run's message says its deck is kept."""
    kept = Path(re.search(r"(\S*hexdem-failed-\w+/deck)", message).group(1))
    assert kept.is_dir()
    return kept


@pytest.mark.parametrize(
    "config_text, message",
    [
        ("edge_beads = 1", "at least 2 beads per edge"),
        ("v0 = 0.0", "v0 must be > 0"),
        ("v0 = -0.4", "v0 must be > 0"),
        ("strike_angle_deg = 95", "strike angle 95"),
        ('shape = "pentagon"', "unknown shape 'pentagon'"),
        ("diameter_m = -0.01", "bead diameter must be > 0"),
        ("ranks = 0", "ranks must be a positive integer"),
        ("velocity = 0.4", "unknown parameter velocity; the keys are angle_deg, bead_material, "),
        ("edge_beds = 7", "unknown parameter edge_beds; did you mean edge_beads"),
        ("v0 = [", "not valid TOML"),
        ('shape = "sites"\nsites = [[0, 0], [2, 0], [0, 0]]', "site {0, 0} is listed twice"),
        ('shape = "sites"\nsites = [[2, 0], [4, 0]]', "the struck site {0, 0} is not in the packing"),
        ('shape = "sites"\nsites = [[0, 0], [1, 0]]', "m + n odd"),
        ('shape = "sites"\nsites_file = "missing.csv"', "cannot read sites_file missing.csv"),
        ("vacancies = [[0, 0]]", "the struck bead cannot be a vacancy"),
        ("vacancies = [[40, 2]]", "vacancy {40, 2} is not a site"),
        ('shape = "triangle"\nedge_beads = 2', "a triangle needs at least 3 beads per edge"),
        ('shape = "parallelogram"\ndepth_beads = 1', "a parallelogram needs depth_beads >= 2"),
        ('shape = "parallelogram"\ndepth_beads = 0', "a parallelogram needs depth_beads >= 2, got 0"),
        ('bead_material = "unobtainium"', "unobtainium"),
        ('shape = "disc"\nradius_beads = 1', "a disc needs a radius of at least 2 bead diameters"),
        ('shape = "disc"\nradius_beads = 5\nprecompression_n = 20.0', "precompression is built for flat-walled basins"),
        ('edge_beads = "abc"', "edge_beads must be an integer, got 'abc'"),
        ("edge_beads = 5.0", "edge_beads must be an integer, got 5.0"),
        ("initial_state_file = 3", "initial_state_file must be a string, got 3"),
        ('initial_state_file = {path = "state.csv"}', "initial_state_file must be a string, got {'path': 'state.csv'}"),
        ("dump = 1", "dump must be true or false, got 1"),
        ("v0 = nan", "v0 must be a number, got nan"),
        ('sensors = ["0:1", 1.5]', "sensors.1 must be a string or an integer, got 1.5"),
        ("vacancies = [[1, 1, 1]]", "vacancies.0 must be a list of 2 integers, got [1, 1, 1]"),
        ('[[regions]]\nmaterial = "brass"\nx_min_d = "far"', "regions.0.x_min_d must be a number, got 'far'"),
        ("[[impacts]]\nsite = [0, 0]\nkind = 1", "impacts.0.kind must be a string, got 1"),
        ('[materials.bronze]\nyoungs_modulus_pa = "stiff"', "materials.bronze.youngs_modulus_pa must be a number"),
        ('shape = "chain"\nstruck_bead = 3', "struck_bead describes shape = \"packing\", not 'chain'"),
        ("struck_bead = 3", "struck_bead describes shape = \"packing\", not 'hexagon'"),
        ('shape = "square"\nwalls = "hull"', 'walls describes shape = "packing" or "random", not \'square\''),
        (
            'shape = "square"\ninterstitial_diameter_m = 0.008',
            'interstitial_diameter_m describes shape = "centered-square"',
        ),
        ('shape = "square"\ndiameters_m = [0.02]', "diameters_m describes shape = \"chain\", not 'square'"),
        ('shape = "square"\nbead_materials = ["brass"]', "bead_materials describes shape = \"chain\", not 'square'"),
        (
            'shape = "square"\n[[lines]]\nname = "up"\nsite = [0, 0]\nangle_deg = 90',
            'lines describes shape = "hexagon", "half-hexagon", "half-disc", "triangle", "parallelogram", "disc" '
            'or "sites"',
        ),
        ('shape = "random"\nstruck_bead = 2', "struck_bead describes shape = \"packing\", not 'random'"),
        ("rows = 5", 'rows describes shape = "square" or "centered-square", not \'hexagon\''),
        ('shape = "chain"\nedge_beads = 5', 'edge_beads describes shape = "hexagon", "triangle" or "parallelogram"'),
        # a key written is set whatever its value, its default included
        (
            'shape = "square"\nedge_beads = 11',
            'edge_beads describes shape = "hexagon", "triangle" or "parallelogram", not \'square\'',
        ),
        ('shape = "chain"\nwall_material = "delrin"', 'wall_material describes shape = "hexagon", '),
        ('engine = "reference"\nranks = 1', "ranks does nothing: the reference engine runs in one process"),
        ("sensor_rate_hz = 500e3", "sensor_rate_hz does nothing: there are no sensors"),
        ('materials = ["brass"]', "a chain's material per bead goes in bead_materials"),
        ('shape = "chain"\nwall_friction = 0.3', 'wall_friction describes shape = "hexagon", "half-hexagon", '),
        (
            'striker_material = "brass"',
            'striker_material does nothing: no impact is a striker (impact = "velocity"); '
            'set impact = "striker" or remove it',
        ),
        (
            'striker_diameter_m = 0.01\n[[impacts]]\nsite = [0, 0]\nkind = "velocity"',
            'striker_diameter_m does nothing: no [[impacts]] table is a striker; set kind = "striker" on one',
        ),
        ("sensor_rate_hz = 1e6", "sensor_rate_hz does nothing: there are no sensors; add sensors or remove it"),
        ("sensor_mass_factor = 2.0", "sensor_mass_factor does nothing: there are no sensors"),
        (
            'wall_material = "none"\nwall_restitution = 0.9',
            'wall_restitution does nothing: the packing has no walls (wall_material = "none"); name a wall material',
        ),
        (
            'shape = "random"\nwall_material = "brass"',
            'wall_material does nothing: the packing has no walls (walls = "none"); set walls = "hull" or remove it',
        ),
        (
            'engine = "reference"\nranks = 2',
            "ranks does nothing: the reference engine runs in one process and writes no "
            'dump (engine = "reference"); use engine = "lammps" or remove it',
        ),
        ('engine = "reference"\ndump = true', "dump does nothing: the reference engine runs in one process"),
        (
            'shape = "chain"\nangle_deg = 180.0\nstrike_angle_deg = 0.0',
            "strike angle 0.0° does not point into the packing, which lies at 180° from its struck bead",
        ),
    ],
)
def test_bad_config_is_one_line_and_writes_nothing(tmp_path, capsys, config_text, message):
    code, err = run_cli(tmp_path, capsys, config_text)
    assert code == 3
    assert len(err) == 1 and err[0].startswith("hexdem: error:") and message in err[0]
    assert_no_results(tmp_path / "out")


@pytest.mark.parametrize("name", [field.name for field in dataclasses.fields(RunConfig)])
def test_every_key_is_checked_against_its_declared_type(name):
    """A table where any other value belongs (a number for ``materials``, which takes a table or a
    list of names) is refused in one line naming the key, the type and the value."""
    wrong = 3 if name == "materials" else {"a": 1}
    with pytest.raises(HexdemError) as error:
        RunConfig(**{name: wrong})
    assert str(error.value).startswith(f"{name} must be ") and str(error.value).endswith(f", got {wrong!r}")


def test_a_bead_far_from_the_others_is_one_line(tmp_path, capsys):
    """A packing file with a bead at 1e30 m (a ValueError traceback before)."""
    (tmp_path / "far.csv").write_text("x,y,diameter\n0,0,0.01905\n0.01905,0,0.01905\n1e30,0,0.01905\n")
    code, err = run_cli(tmp_path, capsys, f'shape = "packing"\npacking_file = "{tmp_path / "far.csv"}"')
    assert (
        code == 3
        and len(err) == 1
        and "the beads span 1e+30 m, more than 10 times all 3 of them laid end to end" in err[0]
    )
    assert_no_results(tmp_path / "out")


def test_input_files_that_are_not_utf8_are_one_line(tmp_path, capsys):
    """A configuration and a sites file saved in Latin-1 (the ® is byte 0xae, the 33rd)."""
    latin = tmp_path / "latin.toml"
    latin.write_bytes('bead_material = "ptfe"  # Teflon®\n'.encode("latin-1"))
    (tmp_path / "sites.csv").write_bytes("m,n\n0,0\n2,0  # ®\n".encode("latin-1"))
    (tmp_path / "sites.toml").write_text(f'shape = "sites"\nsites_file = "{tmp_path / "sites.csv"}"\n')
    for config, message in (
        (latin, f"config {latin} is not UTF-8 text (byte 32: {bytes([0xAE])!r})"),
        (tmp_path / "sites.toml", f"sites_file {tmp_path / 'sites.csv'} is not UTF-8 text"),
    ):
        assert main(["run", "--config", str(config), "--out", str(tmp_path / "out")]) == 3
        lines = capsys.readouterr().err.strip().splitlines()
        assert len(lines) == 1 and message in lines[0], lines
        assert_no_results(tmp_path / "out")


@pytest.fixture(scope="module")
def small_deck(tmp_path_factory):
    """The deck of a 4-per-edge hexagon's run with its dump (37 beads, 1 ms)."""
    out = tmp_path_factory.mktemp("small") / "out"
    run_experiment(RunConfig(edge_beads=4, duration=1e-3, dump=True), out, log=lambda message: None)
    return out / "deck"


@pytest.mark.parametrize(
    "text, message",
    [
        ("[1, 2]", "hexdem.json holds [1, 2] where a table of run-config keys belongs"),
        ("null", "hexdem.json holds null where a table of run-config keys belongs"),
        ('{"edge_beads": "four"}', "edge_beads must be an integer, got 'four'"),
        (json.dumps(RunConfig(edge_beads=5, duration=1e-3, dump=True).as_dict()), "holds 37 atoms, the packing of"),
    ],
)
def test_analyse_refuses_a_damaged_deck_in_one_line(small_deck, tmp_path, capsys, text, message):
    """``hexdem.json`` of the wrong shape, of wrong types, or of another packing than the dump's
    (61 beads for the dump's 37, the same frames)."""
    deck = tmp_path / "deck"
    deck.mkdir()
    for entry in small_deck.iterdir():
        (deck / entry.name).symlink_to(entry)
    (deck / "hexdem.json").unlink()
    (deck / "hexdem.json").write_text(text)
    assert main(["analyse", str(deck), "--out", str(tmp_path / "analysed")]) == 3
    lines = [line for line in capsys.readouterr().err.strip().splitlines() if not line.startswith("hexdem analyse: ")]
    assert len(lines) == 1 and message in lines[0], lines
    assert_no_results(tmp_path / "analysed")


def test_unwritable_output_directory(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    code, err = run_cli(tmp_path, capsys, out=blocker / "out")
    assert code == 3 and len(err) == 1 and "is not writable" in err[0]


def test_lammps_failure_names_lammps_message_and_the_kept_deck(tmp_path, capsys, monkeypatch):
    render = deck.render_input
    monkeypatch.setattr(deck, "render_input", lambda *args: render(*args).replace("timestep ", "timestpe "))
    code, err = run_cli(tmp_path, capsys, "edge_beads = 3")
    out = tmp_path / "out"
    assert code == 4 and len(err) == 1
    assert "LAMMPS failed on" in err[0] and "ERROR: Unknown command: timestpe" in err[0]
    assert "in.hexdem" in err[0] and (kept_deck(err[0]) / "log.lammps").exists()
    assert_no_results(out)


def test_time_step_not_small_against_the_contact_is_refused_before_running(tmp_path, capsys):
    """dt = 2e-5 s against the 71.7 µs two-bead contact at 0.4 m/s: fewer than 20 steps per contact."""
    code, err = run_cli(tmp_path, capsys, "edge_beads = 5\ndt = 2e-5\nduration = 1e-3")
    assert code == 3 and len(err) == 1 and "not small against the Hertz contact time 7.17e-05" in err[0]
    assert "hexdem-failed-" not in err[0]
    assert_no_results(tmp_path / "out")


def test_run_whose_energy_drifts_is_refused(tmp_path, capsys):
    """dt = τ/24 passes the step check, but its energy drift (≈ 2e-6 · (700/24)² ≈ 2e-3) does not."""
    code, err = run_cli(tmp_path, capsys, "edge_beads = 5\ndt = 3e-6\nduration = 1e-3\ndump_every = 2")
    assert code == 4 and len(err) == 1 and "energy drift" in err[0] and "time step" in err[0]
    assert (kept_deck(err[0]) / "in.hexdem").exists()
    assert_no_results(tmp_path / "out")


@pytest.mark.parametrize(
    "config_text, message",
    [
        ("dt = 1e-3", "not small against the Hertz contact time"),
        ("dump_every = 2000", "too few samples to analyse"),
        ("duration = 1e-6", "too few samples to analyse"),
        ("edge_beads = 100000", "needs about"),
        ('shape = "half-hexagon"\nshort_edge = 40000\nlong_edge = 79999', "needs about"),
        ('shape = "square"\nrows = 100000\ncolumns = 100000', "square of up to 10,000,000,000 beads needs about"),
        ('shape = "chain"\nbeads = 10000000000', "chain of up to 10,000,000,000 beads needs about"),
        ('shape = "random"\nradius_m = 1000.0', "random of up to"),
        ("precompression_n = 1e12", "precompression_n = 1e+12 N would squeeze each contact by 1.15e+03 diameters"),
        ('shape = "square"\nrows = 1\ncolumns = 1', "a square crystal needs at least 2 rows and 2 columns, got 1 x 1"),
        ('shape = "sites"\nsites = [[0, 0]]', "a packing needs at least 2 beads, or 1 bead and a wall to rebound from"),
        (
            'shape = "sites"\nsites = [[0, 0], [1, 1], [0, 2000000000]]',
            "3 listed sites: the beads span 3.3e+07 m, more than 10 times all 3",
        ),
        ('shape = "chain"\nbeads = 3\ndiameters_m = [0.02, 1e30, 0.02]', "not within a factor 10 of diameter_m"),
    ],
)
def test_runs_that_cannot_be_analysed_or_cannot_fit_are_refused(tmp_path, capsys, config_text, message):
    code, err = run_cli(tmp_path, capsys, config_text)
    assert code == 3 and len(err) == 1 and message in err[0]
    assert_no_results(tmp_path / "out")


@pytest.mark.parametrize("ranks", [1, 2])
def test_deck_error_is_reported_with_lammps_message(tmp_path, capfd, ranks):
    """By hand (``lmp -in``) and through the streaming driver on 1 and 2 MPI ranks; the ranks
    that abort print no traceback."""
    config = RunConfig(edge_beads=3)
    rendered = write_deck(build_model(config), settings_of(config), tmp_path / "deck")
    rendered.input_path.write_text(
        rendered.input_path.read_text().replace("pair_style      gran/hertz/history", "pair_style nonsense")
    )
    for attempt in (
        lambda: run_bare(rendered, ranks),
        lambda: run_on_ranks(functools.partial(run_streaming, rendered, repr), ranks, tmp_path / "job"),
    ):
        with pytest.raises(HexdemError, match=r"LAMMPS failed on .*in\.hexdem: ERROR: .*nonsense") as info:
            attempt()
        assert "\n" not in str(info.value)
    assert "Traceback" not in capfd.readouterr().err


def test_corrupt_dump_is_a_clear_error(tmp_path):
    dump = tmp_path / "dump.lammpstrj"
    dump.write_text("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n3\nthis is not a dump\n")
    with pytest.raises(HexdemError, match="corrupt"):
        read_dump(dump, 1e-7)
    with pytest.raises(HexdemError, match="does not exist"):
        read_dump(tmp_path / "missing", 1e-7)


def test_truncated_dump_is_a_clear_error(dumped_run, tmp_path):
    text = (dumped_run[0] / "deck" / "dump.lammpstrj").read_text()
    dump = tmp_path / "dump.lammpstrj"
    dump.write_text(text[: len(text) // 2])
    settings = dumped_run[1].settings
    with pytest.raises(HexdemError, match=f"truncated: .* of {settings.n_samples} frames"):
        read_dump(dump, settings.dt_s, settings.n_samples)


def test_missing_lammps_module(monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "lammps", None)
    with pytest.raises(HexdemError, match="LAMMPS Python module is not installed"):
        library.load_lammps.__wrapped__()


def test_lammps_loads_without_ld_library_path():
    lammps = library.load_lammps()
    instance = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    try:
        assert instance.has_package("GRANULAR")
    finally:
        instance.close()
    assert library.mpi_library_path().name == "libmpi.so.12"
    assert np.isfinite(float(instance.version()))


def test_an_observer_failing_on_two_ranks_is_one_line(tmp_path, capfd):
    """The failing rank aborts the MPI job (the others would wait in a collective call) and its
    message reaches the user through job.error."""
    config = RunConfig(edge_beads=3)
    rendered = write_deck(build_model(config), settings_of(config), tmp_path / "deck")
    with pytest.raises(RunFailed, match="TypeError: object of type 'Sample' has no len") as info:
        run_on_ranks(functools.partial(run_streaming, rendered, len), 2, tmp_path / "job")
    assert "\n" not in str(info.value)
    assert "Traceback" not in capfd.readouterr().err


def test_a_rank_that_refuses_its_input_is_a_refusal_and_a_failing_one_a_failed_run(tmp_path):
    """The kind of a rank's error reaches the launching process with its message: a
    :class:`HexdemError` stays a refusal (the command's status 3), anything else is a failed run
    (:class:`RunFailed`, status 4)."""
    config = RunConfig(edge_beads=3)
    rendered = write_deck(build_model(config), settings_of(config), tmp_path / "deck")
    refusing = functools.partial(run_streaming, rendered, functools.partial(positive_int, "--beads"))
    with pytest.raises(HexdemError, match="--beads must be a positive integer, got Sample") as info:
        run_on_ranks(refusing, 2, tmp_path / "job")
    assert not isinstance(info.value, RunFailed)
    assert reported_error("LAMMPS failed on in.hexdem: ERROR: Lost atoms\nfailed\n").args == (
        "LAMMPS failed on in.hexdem: ERROR: Lost atoms",
    )
    assert isinstance(reported_error("a report without its kind\n"), RunFailed)


@pytest.mark.parametrize(
    "keys",
    [
        {"impact": "striker", "striker_material": "brass", "striker_diameter_m": 0.01},
        {"impacts": ({"site": (0, 0), "kind": "striker"},), "striker_material": "brass"},
        {"sensors": ("0:1",), "sensor_rate_hz": 1e6, "sensor_mass_factor": 2.0},
        {"wall_material": "none"},
        {"shape": "random", "walls": "hull", "wall_material": "brass", "wall_restitution": 0.9, "wall_friction": 0.2},
        {"shape": "random", "wall_material": "none"},
        {"engine": "reference", "launcher": "mpiexec"},
        {"ranks": 2, "dump": True},
    ],
    ids=[
        "striker",
        "a striker among the impacts",
        "sensors",
        "no walls",
        "a random disc's hull",
        "none, said twice",
        "a launched reference run",
        "LAMMPS's ranks and dump",
    ],
)
def test_the_keys_refused_where_idle_are_taken_where_they_act(keys):
    """The other side of the refusals above: each key is taken where what the others say makes it act."""
    from hexdem.model.unused_keys import check_unused_keys, set_idle_keys

    config = RunConfig(**keys)
    assert set_idle_keys(config) == {}
    check_unused_keys(config)


def test_a_striker_key_left_idle_by_the_impact_tables_names_them():
    """With [[impacts]] tables, each table's kind decides: the refusal points at the tables, not at
    the run-wide ``impact`` they override."""
    from hexdem.model.unused_keys import check_unused_keys

    config = RunConfig(impact="striker", striker_material="brass", impacts=({"site": (0, 0), "kind": "velocity"},))
    with pytest.raises(
        HexdemError,
        match=r"^striker_material does nothing: no \[\[impacts\]\] table is a striker; "
        r'set kind = "striker" on one or remove it$',
    ):
        check_unused_keys(config)


def test_derived_configurations_may_leave_a_users_key_idle():
    """A random disc is packed on a configuration stripped of its walls, impacts and sensors: what the
    user's configuration uses, the stripped one leaves idle, and is not refused for it."""
    from hexdem.model.unused_keys import check_unused_keys, set_idle_keys

    user = RunConfig(shape="random", walls="hull", wall_material="brass", sensors=("0:1",), sensor_rate_hz=1e6)
    check_unused_keys(user)
    stripped = user.replace(walls="none", sensors=())
    assert set(set_idle_keys(stripped)) == {"wall_material", "sensor_rate_hz"}


def test_compare_checks_a_files_keys_as_lammps_takes_them(tmp_path):
    """``hexdem compare`` ignores the file's engine: a file for the reference engine with --ranks 2
    is taken, its LAMMPS side on 2 ranks (the reference side takes one, ``on_engine``)."""
    from hexdem.cli.main import build_parser
    from hexdem.cli.run import config_from_args

    path = tmp_path / "reference.toml"
    path.write_text('engine = "reference"\n')
    args = build_parser(["compare"]).parse_args(["compare", "--config", str(path), "--ranks", "2"])
    config = config_from_args(args)
    assert (config.engine, config.ranks) == ("lammps", 2)


def test_a_configuration_handed_to_both_engines_keeps_lammps_keys_for_lammps_alone():
    """``hexdem compare`` and sweeps that vary ``engine`` run one configuration on both engines:
    LAMMPS keeps its ranks and dump, the reference engine takes one process and no dump."""
    from hexdem.model.unused_keys import on_engine

    config = RunConfig(ranks=2, dump=True, launcher="mpiexec")
    lammps, reference = on_engine(config, "lammps"), on_engine(config, "reference")
    assert (lammps.engine, lammps.ranks, lammps.dump, lammps.launcher) == ("lammps", 2, True, "mpiexec")
    assert (reference.engine, reference.ranks, reference.dump, reference.launcher) == ("reference", 1, False, "mpiexec")


def test_the_python_api_refuses_an_idle_key_as_the_command_does():
    from hexdem.api import simulate_impact

    with pytest.raises(
        HexdemError, match="^sensor_rate_hz does nothing: there are no sensors; add sensors or remove it$"
    ):
        simulate_impact(sensor_rate_hz=1e6)
