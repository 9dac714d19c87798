"""What a frictional run reports: each bead's peak spin (``beads.csv`` ``peak_angular_speed``) and
the largest share of the energy held in rotation (``summary.json`` ``rotational_energy_fraction``),
read by the tracker inside the run in both engines, against the gross-sliding limit worked out by
hand; frictionless runs report spheres that never turn."""

import json

import numpy as np
import pytest
from conftest import V0, D, read_csv
from oblique import INERTIA, sphere_on_wall

from hexdem.cli.main import main
from hexdem.experiments.tracked_run import ImpactJob, track_impact
from hexdem.model.granular import RunSettings
from hexdem.model.hertz import contact_time
from hexdem.model.materials import effective_modulus

#: Incidence [deg] and μ of a sphere that slides all through its contact with the wall: tan θ = 1.73
#: is more than (7/2)(1 + e)μ = 0.7, the bound below which the contact sticks at some point.
INCIDENCE_DEG, MU = 60.0, 0.1


def gross_sliding() -> tuple[float, float]:
    """(|ω| after the impact [rad/s], its share of the energy) of the sphere on the wall, elastic
    (e = 1): the tangential impulse is μ times the normal one, 2 m v_n, so ω r = (5/2) μ (1 + e) v_n
    (I = (2/5) m r²) and v_t' = v_t − μ (1 + e) v_n, v_n' = e v_n; the energy is all kinetic again."""
    v_n, v_t = V0 * np.cos(np.radians(INCIDENCE_DEG)), V0 * np.sin(np.radians(INCIDENCE_DEG))
    r = D / 2
    omega = 2.5 * MU * 2 * v_n / r
    rotational = 0.5 * INERTIA * r**2 * omega**2  # per unit mass
    translational = 0.5 * (v_n**2 + (v_t - 2 * MU * v_n) ** 2)
    return omega, rotational / (rotational + translational)


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_the_tracker_reports_the_spin_and_rotational_share_of_gross_sliding(tmp_path, engine):
    model = sphere_on_wall(INCIDENCE_DEG, MU)
    v_n = V0 * np.cos(np.radians(INCIDENCE_DEG))
    hertz = (4 / 3) * effective_modulus(model.bead, model.wall) * np.sqrt(D / 2)  # F = A δ^{3/2} against a plane
    tau = float(contact_time(model.masses_kg[0], hertz, v_n))
    settings = RunSettings(dt_s=tau / 2000, n_steps=4000, dump_every=20, contact_time_s=tau)
    last = settings.n_samples - 1
    analysis = track_impact(ImpactJob(model, settings, engine, tmp_path, show_progress=False, field_samples=(0, last)))
    omega, share = gross_sliding()
    assert analysis.results.peak_angular_speed[0] == pytest.approx(omega, rel=1e-5)
    assert analysis.results.rotational_energy_fraction == pytest.approx(share, rel=1e-4)
    assert share > 0.01
    rim = analysis.tracked.field_rim_speeds[:, 0]  # the spin movie's frames: at rest, then ω r
    assert rim[0] == 0.0 and rim[1] == pytest.approx(omega * D / 2, rel=1e-5)


def test_frictionless_spheres_report_no_spin_and_frictional_ones_do(tmp_path):
    """beads.csv's peak_angular_speed and summary.json's share: 0 without friction; with μ = 0.3 the
    struck bead turns and rotation holds a share of the energy (the default experiment, 4 per edge);
    a movie of the spin comes with the movie of the speeds where the spheres turn."""
    for friction in (0.0, 0.3):
        out = tmp_path / str(friction)
        config = tmp_path / f"{friction}.toml"
        config.write_text(f"edge_beads = 4\nstrike_angle_deg = 20.0\nfriction = {friction}\n")
        assert main(["run", "--config", str(config), "--out", str(out), "--movie"]) == 0
        assert (out / "movie.gif").exists() and (out / "spin_movie.gif").exists() == (friction > 0)
        _, beads = read_csv(out / "beads.csv")
        spins = np.array([float(row["peak_angular_speed"]) for row in beads])
        share = json.loads((out / "summary.json").read_text())["rotational_energy_fraction"]
        if friction == 0.0:
            assert np.all(spins == 0.0) and share == 0.0
        else:
            assert np.count_nonzero(spins > 0) > len(spins) // 2 and 0.0 < share < 0.5
