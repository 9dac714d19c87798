"""Shared fixtures: one real LAMMPS run of the paper's default experiment per test session."""

import numpy as np
import pytest

from hexdem.config import RunConfig
from hexdem.experiment import run_experiment
from hexdem.lattice import Lattice


@pytest.fixture(scope="session")
def default_run(tmp_path_factory):
    """``hexdem run`` with no options (11 per edge, steel, delrin walls, 0.4 m/s, 0°)."""
    out = tmp_path_factory.mktemp("default")
    analysis = run_experiment(RunConfig(), out, log=lambda message: None)
    return out, analysis


def single_bead(diameter_m=0.01905) -> Lattice:
    """A one-bead 'packing' at the origin, for two-body collisions with a striker or a wall."""
    return Lattice(indices=np.array([[0, 0]]), positions_m=np.zeros((1, 2)),
                   diameters_m=np.array([diameter_m]), diameter_m=diameter_m,
                   struck=0, walls=(), shape="single bead")
