"""The compiled per-sample kernels (:mod:`hexdem.analysis.compiled`) compute what the NumPy
tracker and energy audit compute: the same run analysed both ways gives the same peaks, times and
velocities to the bit, and the same energies to round-off (the compiled audit sums body by body,
NumPy in pairs)."""

import numpy as np
import pytest

import hexdem.common.compiled as compiled
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig

RUNS = {
    "hexagon": {"edge_beads": 8},
    "striker, friction, brass region": {"edge_beads": 7, "impact": "striker", "friction": 0.3,
                                        "regions": ({"material": "brass", "x_min_d": 3.0},)},
    "square": {"shape": "square", "rows": 9, "columns": 9},
}


@pytest.mark.parametrize("changes", RUNS.values(), ids=RUNS)
def test_the_compiled_kernels_give_the_numpy_results(tmp_path, monkeypatch, changes):
    config = RunConfig(**changes)
    numpy_run = simulate(config, tmp_path / "numpy").tracked
    monkeypatch.setattr(compiled, "COMPILED_BEADS", 1)
    compiled_run = simulate(config, tmp_path / "compiled").tracked
    for name in ("peak_speed", "t_peak", "arrival_time", "reach_time", "end_velocity", "peak_angular_speed"):
        np.testing.assert_array_equal(getattr(compiled_run, name), getattr(numpy_run, name), err_msg=name)
    np.testing.assert_allclose(compiled_run.region_energies, numpy_run.region_energies, rtol=1e-12, atol=0)
    assert compiled_run.energy_drift == pytest.approx(numpy_run.energy_drift, rel=1e-6, abs=1e-12)
    assert compiled_run.rotational_energy_fraction == pytest.approx(numpy_run.rotational_energy_fraction, rel=1e-9)


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

    code = ("import sys, threading; from hexdem.common.preload import load_in_background; "
            "load_in_background('colorsys', 'hexdem_no_such_module'); "
            "[t.join() for t in threading.enumerate() if t is not threading.main_thread()]; "
            "print('colorsys' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "True" and done.stderr == ""
