"""The compiled per-sample kernels (:mod:`hexdem.analysis.compiled`) compute what the NumPy
tracker and energy audit compute: the same run analysed both ways gives the same peaks, times and
velocities to the bit, and the same energies to round-off (the compiled audit sums body by body,
NumPy in pairs)."""

import numpy as np
import pytest
from conftest import settings_of

import hexdem.analysis.tracker as tracker_module
import hexdem.common.kernel_switch as compiled
from hexdem.analysis.compiled import sample_pulses
from hexdem.analysis.energy import EnergyAudit, _pair_constants, _pair_contacts, _pairs, _wall_constants, _wall_contacts
from hexdem.analysis.tracker import PulseTracker
from hexdem.analysis.tracker_kernel import RIVAL_RATIO, SAMPLED, PulseState
from hexdem.engines.sampling import Sample
from hexdem.errors import HexdemError
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

RUNS = {
    "hexagon": {"edge_beads": 8},
    "striker, friction, brass region": {
        "edge_beads": 7,
        "impact": "striker",
        "friction": 0.3,
        "regions": ({"material": "brass", "x_min_d": 3.0},),
    },
    "square": {"shape": "square", "rows": 9, "columns": 9},
    "chain with an intruder": {
        "shape": "chain",
        "beads": 20,
        "duration": 1e-3,
        "intruders": ({"bead": 10, "diameter_m": 0.009525},),
    },
    "disc": {"shape": "disc", "radius_beads": 6},
}


@pytest.mark.parametrize("changes", RUNS.values(), ids=RUNS)
def test_the_compiled_kernels_give_the_numpy_results(tmp_path, monkeypatch, changes):
    config = RunConfig(**changes)
    passes = []  # the compiled tracker's passes, so that each run is known to have taken its way
    monkeypatch.setattr(
        tracker_module, "sample_pulses", lambda *args, **named: passes.append(1) or sample_pulses(*args, **named)
    )
    monkeypatch.setattr(compiled, "COMPILED", False)
    numpy_run = simulate(config, tmp_path / "numpy").tracked
    assert not passes
    monkeypatch.setattr(compiled, "COMPILED", True)
    compiled_run = simulate(config, tmp_path / "compiled").tracked
    assert len(passes) == compiled_run.n_samples
    for name in ("peak_speed", "t_peak", "arrival_time", "reach_time", "end_velocity", "peak_angular_speed"):
        np.testing.assert_array_equal(getattr(compiled_run, name), getattr(numpy_run, name), err_msg=name)
    # the two ways round each overlap δ (a difference of coordinates ~10 D) differently, by ~1e-15 D (the
    # compiled walls take n·x term by term, NumPy's BLAS as it likes): a contact's energy ∝ δ^{5/2} moves by
    # 2.5e-15 D / δ of itself, under 1e-9 for δ ≥ 1e-5 D, and smaller overlaps hold little of the run's
    # energy, which the audit's figures are read against
    np.testing.assert_allclose(
        compiled_run.region_energies, numpy_run.region_energies, rtol=0, atol=1e-9 * numpy_run.region_energies[0].sum()
    )
    assert compiled_run.energy_drift == pytest.approx(numpy_run.energy_drift, rel=1e-6, abs=1e-12)
    assert compiled_run.rotational_energy_fraction == pytest.approx(numpy_run.rotational_energy_fraction, rel=1e-9)


@pytest.mark.parametrize(
    "changes, gravity_m_s2",
    [
        ({"edge_beads": 6}, None),
        ({"shape": "disc", "radius_beads": 5}, None),
        ({"edge_beads": 5, "regions": ({"material": "brass", "x_min_d": 2.0},)}, None),
        ({"edge_beads": 6}, (3.0, -9.81)),
    ],
    ids=["flat walls", "curved wall", "two materials", "gravity"],
)
def test_the_compiled_audit_is_the_numpy_audit_of_a_squeezed_packing(changes, gravity_m_s2):
    """Every body pushed outwards by a ten-thousandth of its distance from the centre, then moved at
    random by up to 1e-5 of a diameter: the beads along the walls overlap them and some pairs
    overlap, so both the wall and the pair sums count, on a share of the bodies with the rest as
    ghosts (in a random order); with gravity, its work on the moved bodies counts too.

    The two ways round differently only in the overlaps δ, differences of coordinates |x| up to
    X: each δ within a few ulps of X, 8 ε X, so each contact's energy within its force
    k √R δ^{3/2} (dU/dδ) times that."""
    model = build_model(RunConfig(**changes))
    rng = np.random.default_rng(0)
    start = model.initial_positions_m()
    squeezed = (
        start + 1e-4 * (start - start.mean(axis=0)) + 1e-5 * model.packing.diameter_m * rng.uniform(-1, 1, start.shape)
    )
    velocities, bodies, n_own = rng.standard_normal(start.shape), rng.permutation(model.n_bodies), model.n_bodies // 2
    radii = model.diameters_m / 2
    pairs = _pair_contacts(squeezed, radii, _pair_constants(model, *_pairs(squeezed, 2 * radii.max()), radii))[2:]
    walls = [wall[1:] for wall in _wall_contacts(squeezed, _wall_constants(model))]
    assert sum(len(wall[0]) for wall in walls) > 0
    forces_n = sum(np.sum(k * np.sqrt(r_eff) * overlap**1.5) for k, r_eff, overlap in [pairs, *walls])
    numpy_part, compiled_part = (
        EnergyAudit(model, gravity_m_s2, compiled=way).part(bodies, n_own, squeezed[bodies], velocities[bodies[:n_own]])
        for way in (False, True)
    )
    assert np.all(numpy_part[4::2] > 0)  # each region's contact energy
    overlap_round_off_m = 8 * np.finfo(float).eps * np.abs(squeezed).max()
    np.testing.assert_allclose(compiled_part, numpy_part, rtol=1e-13, atol=forces_n * overlap_round_off_m)


def test_the_compiled_sample_is_the_numpy_full_step_to_the_bit():
    """LAMMPS's per-atom arrays are (n, 3); the compiled sample takes the first two columns and
    completes the half-step velocities as the NumPy driver does, v + (dt/2 / m) f."""
    from hexdem.engines.lammps.full_step import full_step_state

    rng = np.random.default_rng(7)
    x, v, f = (rng.normal(size=(1000, 3)) * scale for scale in (1e2, 1e-3, 1e4))
    mass, half_dt = rng.uniform(0.5, 2.0, 1000), 0.5 * 2.3e-3
    positions, velocities = full_step_state(x, v, f, mass, half_dt)
    np.testing.assert_array_equal(positions, x[:, :2])
    np.testing.assert_array_equal(velocities, v[:, :2] + (half_dt / mass)[:, None] * f[:, :2])


@pytest.mark.parametrize(
    "count, spread, cutoff",
    [(0, 1.0, 1.0), (1, 1.0, 1.0), (2, 0.0, 0.5), (3000, 50.0, 1.1), (2000, 1.0, 0.1)],
    ids=["none", "one", "two at one place", "sparse", "dense"],
)
def test_the_compiled_pair_search_finds_the_pairs_of_scipys_tree(count, spread, cutoff):
    """Every pair within the cutoff, each once with i < j, as ``cKDTree.query_pairs`` finds them; a
    body knocked a billion cutoffs away (LAMMPS's shrink-wrapped box keeps it) neither hides a pair
    nor makes the search a quadratic one."""
    from scipy.spatial import cKDTree

    from hexdem.analysis.compiled import pairs_within

    positions = np.random.default_rng(count).uniform(0, spread, (count, 2))
    if count > 2:
        positions[-1] = (1e9, -1e9)
    i, j = pairs_within(positions, cutoff)
    found = sorted(zip(i.tolist(), j.tolist()))
    assert found == sorted(map(tuple, cKDTree(positions).query_pairs(cutoff, output_type="ndarray").tolist()))
    assert all(a < b for a, b in found) and (count < 3000 or len(found) > count)
    with pytest.raises(ValueError, match="not finite"):
        pairs_within(np.array([[0.0, 0.0], [np.nan, 1.0]]), cutoff)


def test_the_kernels_refuse_arrays_they_cannot_read_and_indices_outside_them():
    """The C kernels read raw memory: an array of another type, order or shape is a TypeError, and
    a row index outside its array an IndexError, never a read or write past the array's end; a
    sample whose bodies are not the previous sample's is refused with the state as it was."""
    from hexdem.analysis.compiled import BodiesReordered, bind_pulses, sample_pulses

    velocities, ids = np.ones((4, 2)), np.arange(4)
    speeds, end_velocity = np.empty(4), np.empty((4, 2))

    def take(velocities=velocities, rows=ids, speeds=speeds, previous=ids, n=4):
        state = PulseState(n, 8, 0.0)
        return sample_pulses(
            bind_pulses(state),
            ids=ids,
            previous_ids=previous,
            velocities=velocities,
            rows=rows,
            end_velocity=end_velocity[:n],
            speeds=speeds,
            s=0,
        )

    assert len(take()) == 0
    np.testing.assert_array_equal(speeds, np.full(4, np.sqrt(2)))
    with pytest.raises(BodiesReordered, match="not previous_ids"):
        take(previous=ids[::-1].copy())  # other bodies than the previous sample's
    for wrong in (velocities.astype(np.float32), np.ones((4, 3)), np.asfortranarray(np.ones((4, 2)))[::2]):
        with pytest.raises(TypeError, match="velocities"):
            take(velocities=wrong, rows=ids[:2], speeds=speeds[:2], n=2)
    with pytest.raises(TypeError, match=r"speeds: expected float64 \(0 or >= n,\) = \(4,\), got float64 \(3,\)"):
        take(speeds=np.empty(3))  # neither empty nor long enough for its rows
    with pytest.raises(IndexError):
        take(rows=np.array([0, 4]), speeds=speeds[:2], n=2)


def test_the_kernels_take_every_argument_by_name_and_check_it_by_name():
    """The tracker's state is bound by name: an array of the wrong shape under a name, a missing
    name, an unknown one or an argument given by position is refused, naming the argument. Arrays
    of one type and shape (``rec_prev``/``rec_prev2``, ``start``/``length``) are told apart by
    their names alone, and each is checked against its own name's type and shape."""
    from hexdem.common import _kernels

    state = PulseState(5, 8, 0.0)
    arrays, constants = state.kernel_arrays(), {"q": state.q, "rival_ratio": RIVAL_RATIO}
    _kernels.PulseArrays(**arrays, **constants)
    with pytest.raises(TypeError, match="by name"):
        _kernels.PulseArrays(*arrays.values(), *constants.values())
    narrow = dict(arrays, rec_prev2=np.zeros((5, 7)))
    with pytest.raises(
        TypeError, match=r"rec_prev2: expected float64 \(n, capacity\) = \(5, 8\), got float64 \(5, 7\)"
    ):
        _kernels.PulseArrays(**narrow, **constants)
    swapped = dict(arrays, start=state.rec_prev, length=state.start)
    with pytest.raises(TypeError, match=r"start: expected int64 \(n,\) = \(5,\), got float64 \(5, 8\)"):
        _kernels.PulseArrays(**swapped, **constants)
    missing = {name: array for name, array in arrays.items() if name != "length"}
    with pytest.raises(TypeError, match="missing argument length"):
        _kernels.PulseArrays(**missing, **constants)
    with pytest.raises(TypeError, match="no argument named 'rec_prev3'"):
        _kernels.PulseArrays(**arrays, **constants, rec_prev3=state.rec_prev2)
    pulses = _kernels.PulseArrays(**arrays, **constants)
    sample = {
        "ids": np.arange(5),
        "previous_ids": np.arange(5),
        "velocities": np.ones((5, 2)),
        "rows": np.arange(5),
        "end_velocity": np.empty((5, 2)),
        "speeds": np.empty(0),
        "complete": np.empty(5, np.int64),
        "s": 0,
    }
    assert pulses.sample(**sample) == 0
    with pytest.raises(TypeError, match=r"end_velocity: expected float64 \(n, 2\) = \(5, 2\)"):
        pulses.sample(**dict(sample, end_velocity=np.empty((4, 2))))
    with pytest.raises(TypeError, match="PulseArrays.sample: missing argument s"):
        pulses.sample(**{name: value for name, value in sample.items() if name != "s"})


@pytest.mark.parametrize("speeds_wanted", [False, True], ids=["speeds left", "speeds wanted"])
def test_the_compiled_sample_is_the_numpy_update_of_np_hypots_speeds(speeds_wanted):
    """Pulses of random heights passing random beads, with noise, round-off creep, samples a ulp
    around the running maximum and its rival margin, and a bead that never moves: the compiled
    pass (which takes most speeds only when a window needs them) leaves the state, sample by
    sample, as the NumPy update of ``np.hypot``'s speeds leaves it, to the bit, every speed it
    reports included; a slot it left as a velocity holds that velocity."""
    from hexdem.analysis.compiled import bind_pulses, sample_pulses

    rng = np.random.default_rng(11)
    n, samples = 400, 160
    directions = rng.uniform(0, 2 * np.pi, n)
    arrival, height = rng.uniform(0, samples, n), rng.uniform(0.2, 2.0, n)
    t = np.arange(samples)[:, None]
    size = height * np.exp(-0.5 * ((t - arrival) / 3.0) ** 2) * (1 + 0.3 * np.sin(0.9 * t))
    size += 1e-17 * rng.uniform(size=(samples, n))  # creep at round-off
    size[:, 0] = 0.0  # a bead that never moves
    velocities = np.stack([size * np.cos(directions), size * np.sin(directions)], axis=2)
    near = rng.integers(1, samples, 40)  # samples a few ulps about a bead's running maximum, and about its rival margin
    for k, s in enumerate(near):
        bead = 1 + k
        largest = np.hypot(*velocities[:s, bead].T).max()
        level = largest / RIVAL_RATIO if k % 2 else largest
        velocities[s, bead] = (
            np.array([np.cos(directions[bead]), np.sin(directions[bead])]) * level * (1 + (k % 5 - 2) * 1e-16)
        )
    floor = 1e-12
    numpy_state, compiled_state = PulseState(n, 8, floor), PulseState(n, 8, floor)
    pulses = bind_pulses(compiled_state)
    ids, rows, end_velocity = np.arange(n), np.arange(n), np.empty((n, 2))
    left_slots = 0  # ring slots left as velocities, summed over the samples
    for s in range(samples):
        speeds = np.hypot(velocities[s, :, 0], velocities[s, :, 1])
        numpy_state.update(rows, speeds, s)
        taken = np.empty(n if speeds_wanted else 0)
        compiled_state.challenge(
            sample_pulses(
                pulses,
                ids=ids,
                previous_ids=ids,
                velocities=np.ascontiguousarray(velocities[s]),
                rows=rows,
                end_velocity=end_velocity,
                speeds=taken,
                s=s,
            )
        )
        np.testing.assert_array_equal(end_velocity, velocities[s])
        if speeds_wanted:
            np.testing.assert_array_equal(taken, speeds)
        ring = compiled_state.ring.copy()
        left = ring == -1.0
        left_slots += int(left.sum())
        kept = compiled_state.ring_velocity[left]
        ring[left] = np.hypot(kept[:, 0], kept[:, 1])
        np.testing.assert_array_equal(ring, numpy_state.ring, err_msg=f"sample {s}")
        for name in (*SAMPLED[1:], "best_peak", "best_index", "best_offset"):
            np.testing.assert_array_equal(
                getattr(compiled_state, name), getattr(numpy_state, name), err_msg=f"{name}, sample {s}"
            )
    assert (numpy_state.peak_index[1:] >= 0).all() and numpy_state.peak_index[0] == -1  # every moving bead peaked
    assert left_slots == 0 if speeds_wanted else left_slots > 3 * n * samples // 2  # most speeds left untaken
    assert np.isfinite(numpy_state.best_peak).sum() >= 10  # and rivals were refined on both sides


def test_beads_whose_rows_move_keep_the_speeds_their_ring_left_untaken(monkeypatch):
    """The compiled tracker leaves most ring slots as velocities (their speeds untaken); when a
    sample says its bodies may have migrated and lists them in another order, every bead's state,
    those slots included, moves with it. Two pulses pass each bead, the second the larger: the
    window of its new maximum reads the slots of the calm samples before it. Fed once in the
    bodies' order and once reordered every seventh sample: the same results, and the NumPy
    tracker's, to the bit."""
    config = RunConfig(edge_beads=6)
    model = build_model(config)
    settings = run_settings(config, model)
    rng = np.random.default_rng(5)
    n, samples = model.n_bodies, settings.n_samples
    first, height = rng.uniform(0, samples / 2, n), rng.uniform(0.05, 0.2, n)
    second, rise = first + rng.uniform(10, samples / 2, n), rng.uniform(1.2, 2.0, n)
    t = np.arange(samples)[:, None]
    size = height * (np.exp(-0.5 * ((t - first) / 1.5) ** 2) + rise * np.exp(-0.5 * ((t - second) / 1.5) ** 2)) + 1e-17
    direction = rng.uniform(0, 2 * np.pi, n)
    velocities = np.stack([size * np.cos(direction), size * np.sin(direction)], axis=2)
    ids, positions = np.arange(1, n + 1), model.initial_positions_m()

    def tracked(compiled_way, reorder):
        monkeypatch.setattr(compiled, "COMPILED", compiled_way)
        tracker = PulseTracker(model, settings, trace_beads=(0, n // 2))
        order = np.arange(n)
        for s in range(samples):
            moved = s == 0 or (reorder and s % 7 == 0)
            if moved and s:
                order = rng.permutation(n)
            tracker(
                Sample(
                    s,
                    s * settings.dump_every,
                    0.0,
                    ids[order],
                    positions[order],
                    np.ascontiguousarray(velocities[s, order]),
                    migrated=moved,
                )
            )
        return tracker.finish()

    numpy_run, in_order, reordered = tracked(False, False), tracked(True, False), tracked(True, True)
    assert np.isfinite(numpy_run.arrival_time).mean() > 0.9  # pulses passed nearly every bead
    for run in (in_order, reordered):
        for name in ("peak_speed", "t_peak", "arrival_time", "reach_time", "end_velocity", "trace_speeds"):
            np.testing.assert_array_equal(getattr(run, name), getattr(numpy_run, name), err_msg=name)


def test_freed_memory_is_kept_where_the_c_library_can():
    """glibc's ``mallopt`` takes both thresholds; another C library changes nothing and says so."""
    import platform

    from hexdem.common.memory import keep_freed_memory

    assert keep_freed_memory() is (platform.libc_ver()[0] == "glibc")


def test_background_loading_loads_what_it_can_and_prints_nothing():
    """What a run preloads is there when it is first used; a module that cannot load is left to its
    first use, which reports it, and the background thread prints no traceback."""
    import subprocess
    import sys

    code = (
        "import sys, threading; from hexdem.common.preload import load_in_background; "
        "load_in_background('colorsys', 'hexdem_no_such_module'); "
        "[t.join() for t in threading.enumerate() if t is not threading.main_thread()]; "
        "print('colorsys' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "True" and done.stderr == ""


def test_an_in_process_runs_loop_waits_for_what_loads_in_the_background(tmp_path, monkeypatch):
    """The sampling callbacks need the interpreter that a background import holds: an in-process
    run finishes the loading before its loop, so that no sample of the loop finds it under way."""
    import sys

    from hexdem.common.preload import load_in_background
    from hexdem.engines.lammps.deck import write_deck
    from hexdem.engines.lammps.driver import run_streaming

    (tmp_path / "hexdem_slow_module.py").write_text("import time\ntime.sleep(1.0)\nLOADED = True\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    config = RunConfig(edge_beads=3, duration=1e-4)
    deck = write_deck(build_model(config), settings_of(config), tmp_path / "deck")
    loading = []

    def observe(sample):
        loading.append(not hasattr(sys.modules.get("hexdem_slow_module"), "LOADED"))

    load_in_background("hexdem_slow_module")
    run_streaming(deck, observe, show_progress=False)
    assert len(loading) > 2 and not any(loading[1:]), loading  # (the set-up's sample 0 may still find it)


@pytest.mark.parametrize("compiled_way", [False, True], ids=["NumPy", "compiled"])
def test_a_sample_that_reorders_the_bodies_unannounced_is_refused(monkeypatch, compiled_way):
    """A sample's rows are the previous sample's bodies in the same order unless it says that they
    may have migrated: both ways refuse one that swaps two rows without saying so."""
    monkeypatch.setattr(compiled, "COMPILED", compiled_way)
    config = RunConfig(edge_beads=4)
    model = build_model(config)
    tracker = PulseTracker(model, run_settings(config, model))
    ids, positions = np.arange(1, model.n_bodies + 1), model.initial_positions_m()
    velocities = np.zeros_like(positions)
    tracker(Sample(0, 0, 0.0, ids, positions, velocities, migrated=True))
    tracker(Sample(1, 7, 1e-6, ids, positions, velocities, migrated=False))
    swapped = ids.copy()
    swapped[[0, 1]] = swapped[[1, 0]]
    with pytest.raises(HexdemError, match="sample 2 reordered the bodies of rank 0 without saying"):
        tracker(Sample(2, 14, 2e-6, swapped, positions, velocities, migrated=False))


def _kernel_calls():
    """Each kernel's table by name (module.c): a callable taking its arguments by name, a valid set
    of them (a small rank: 3 rows, 2 of them its own, one pair, one wall of one member), and the
    names of the arrays the kernel writes."""
    from hexdem.common import _kernels

    state = PulseState(5, 8, 0.0)
    pulses = dict(state.kernel_arrays(), q=state.q, rival_ratio=RIVAL_RATIO)
    sample = {
        "ids": np.arange(5),
        "previous_ids": np.arange(5),
        "velocities": np.ones((5, 2)),
        "rows": np.arange(5),
        "end_velocity": np.empty((5, 2)),
        "speeds": np.empty(5),
        "complete": np.empty(5, np.int64),
        "s": 0,
    }
    rows = {
        "listed_at": np.zeros((3, 2)),
        "distance": 0.1,
        "i": np.array([0]),
        "j": np.array([1]),
        "contact_m": np.ones(1),
        "coefficient": np.ones(1),
        "region_i": np.zeros(1, np.int64),
        "region_j": np.zeros(1, np.int64),
        "masses": np.ones(2),
        "inertia": np.ones(2),
        "regions": np.zeros(2, np.int64),
        "start": np.zeros((2, 2)),
        "external": np.zeros((2, 2)),
        "curved": np.zeros(1, np.int64),
        "bounds": np.array([0, 1]),
        "points": np.zeros((1, 2)),
        "lengths": np.ones(1),
        "rows": np.array([0]),
        "radii": np.ones(1),
        "wall_coefficient": np.ones(1),
        "wall_regions": np.zeros(1, np.int64),
        "n_regions": 1,
    }
    part = {"positions": np.zeros((3, 2)), "velocities": np.zeros((2, 2)), "spins": np.zeros(0), "sums": np.empty(5)}
    full_step = {
        "masses": np.ones(4),
        "positions": np.ones((4, 3)),
        "velocities": np.ones((4, 3)),
        "forces": np.ones((4, 3)),
        "half_dt": 0.5,
        "x": np.empty((4, 2)),
        "v": np.empty((4, 2)),
    }
    pairs = {"positions": np.zeros((3, 2)), "cutoff": 1.0, "i": np.empty(8, np.int64), "j": np.empty(8, np.int64)}
    pulse_arrays = {name for name, value in pulses.items() if isinstance(value, np.ndarray)}
    return {
        "full_step_state": (_kernels.full_step_state, full_step, {"x", "v"}),
        "pairs_within": (_kernels.pairs_within, pairs, {"i", "j"}),
        "PulseArrays": (_kernels.PulseArrays, pulses, pulse_arrays),
        "PulseArrays.sample": (_kernels.PulseArrays(**pulses).sample, sample, {"end_velocity", "speeds", "complete"}),
        "AuditRows": (_kernels.AuditRows, rows, set()),
        "AuditRows.part": (_kernels.AuditRows(**rows).part, part, {"sums"}),
    }


def _fresh(arguments: dict) -> dict:
    return {name: value.copy() if isinstance(value, np.ndarray) else value for name, value in arguments.items()}


@pytest.mark.parametrize(
    "kernel", ["full_step_state", "pairs_within", "PulseArrays", "PulseArrays.sample", "AuditRows", "AuditRows.part"]
)
def test_every_kernel_refuses_a_read_only_output_a_swap_a_missing_and_an_unknown_name(kernel):
    """Every table of module.c, by name: an array the kernel writes is refused read-only (it would
    be written behind NumPy's back), one it only reads is taken read-only; two arrays of other
    types or shapes swapped, a missing name and an unknown one are refused, each naming the
    argument."""
    call, arguments, written = _kernel_calls()[kernel]
    call(**_fresh(arguments))
    arrays = [name for name, value in arguments.items() if isinstance(value, np.ndarray)]
    for name in arrays:
        frozen = _fresh(arguments)
        frozen[name].flags.writeable = False
        if name in written:
            with pytest.raises(TypeError, match=rf"^{kernel}: {name}: not a C-ordered writable array$"):
                call(**frozen)
        else:
            call(**frozen)
    first = arrays[0]
    other = next(
        name
        for name in arrays
        if (arguments[name].dtype, arguments[name].shape) != (arguments[first].dtype, arguments[first].shape)
    )
    swapped = dict(_fresh(arguments), **{first: arguments[other].copy(), other: arguments[first].copy()})
    with pytest.raises(TypeError, match=rf"^{kernel}: ({first}|{other}): expected"):
        call(**swapped)
    for name in arguments:
        with pytest.raises(TypeError, match=rf"^{kernel}: missing argument {name}$"):
            call(**{key: value for key, value in _fresh(arguments).items() if key != name})
    with pytest.raises(TypeError, match=rf"^{kernel} takes no argument named 'unknown'$"):
        call(**_fresh(arguments), unknown=np.zeros(1))
