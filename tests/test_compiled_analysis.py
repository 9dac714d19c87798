"""The compiled per-sample kernels (:mod:`hexdem.analysis.compiled`) compute what the NumPy
tracker and energy audit compute: the same run analysed both ways gives the same peaks, times and
velocities to the bit, and the same energies to round-off (the compiled audit sums body by body,
NumPy in pairs)."""

import numpy as np
import pytest

import hexdem.analysis.tracker as tracker
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
    monkeypatch.setattr(tracker, "COMPILED_BEADS", 1)
    compiled_run = simulate(config, tmp_path / "compiled").tracked
    for name in ("peak_speed", "t_peak", "arrival_time", "reach_time", "end_velocity", "peak_angular_speed"):
        np.testing.assert_array_equal(getattr(compiled_run, name), getattr(numpy_run, name), err_msg=name)
    np.testing.assert_allclose(compiled_run.region_energies, numpy_run.region_energies, rtol=1e-12, atol=0)
    assert compiled_run.energy_drift == pytest.approx(numpy_run.energy_drift, rel=1e-6, abs=1e-12)
    assert compiled_run.rotational_energy_fraction == pytest.approx(numpy_run.rotational_energy_fraction, rel=1e-9)
