"""``hexdem compare`` with friction: LAMMPS against the reference integrator on the paper's experiment,
a disc, an interface and a double strike, with μ = 0.3 between the spheres and against the walls,
at compare's default tolerances (4 times LAMMPS's expected error at the run's steps per contact),
and on the spheres' spins."""

import numpy as np
import pytest

from hexdem.experiments.compare import run_comparison
from hexdem.model.config import RunConfig
from tests.conftest import read_csv

FRICTION = 0.3


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"shape": "disc", "radius_beads": 6, "impact": "striker", "strike_angle_deg": 20.0},
        {"edge_beads": 7, "regions": [{"material": "brass", "x_min_d": 4.0}], "strike_angle_deg": 10.0},
        {
            "edge_beads": 5,
            "impacts": [
                {"site": [0, 0]},
                {"site": [0, 8], "angle_deg": 180.0, "kind": "striker", "striker_material": "brass"},
            ],
        },
    ],
    ids=["experiment", "disc-striker-20deg", "steel|brass-interface", "double-strike"],
)
def test_engines_agree_with_friction(tmp_path, changes):
    """Peaks and arrivals at the default tolerances; each bead's peak spin within the same relative
    tolerance of the run's largest spin (a spin is a velocity over a radius: the same integration
    error)."""
    config = RunConfig(friction=FRICTION, **changes)
    comparison = run_comparison(config, tmp_path, log=lambda message: None)
    assert comparison.agree, comparison.verdict()
    assert comparison.n_checked > 10
    spins = [
        np.array([float(row["peak_angular_speed"]) for row in read_csv(tmp_path / engine / "beads.csv")[1]])
        for engine in ("lammps", "reference")
    ]
    largest = spins[0].max()
    assert largest > 0 and np.count_nonzero(spins[0]) > len(spins[0]) // 2
    assert np.max(np.abs(spins[0] - spins[1])) <= comparison.tolerances.peak_rel * largest
