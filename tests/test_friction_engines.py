"""The reference integrator with friction (hexdem.engines.reference.friction) on the benchmarks of
Chung & Ooi (2011) in 2D, and against LAMMPS over the whole range of incidence.

As in tests/test_friction_benchmarks.py, every figure is derived (gross sliding: J_t = μ J_n; the
SciPy solution of the one-contact Hertz–Mindlin problem; conservation laws), and each engine's
tolerance comes from its own convergence in the time step (``oblique.convergence_bound``).
"""

import numpy as np
import pytest
from conftest import V0, D, record
from oblique import (
    INERTIA,
    Contact,
    convergence_bound,
    impact_settings,
    lammps_states,
    reference_states,
    solve_contact,
    sphere_in_ring,
    sphere_on_wall,
    sphere_pair,
)

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.reference.engine import ReferenceEngine, ReferenceSystem
from hexdem.engines.reference.friction import FrictionalSystem
from hexdem.model.config import RunConfig
from hexdem.model.materials import STEEL_316
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings
from hexdem.model.units import SI, nondimensional

MU = 0.3
STEPS = 200
#: Incidences, as tan θ / (μ(1 + e)), from sticking (0.05) to gross sliding (6).
NORMALIZED_INCIDENCES = (0.05, 0.2, 0.5, 0.8, 1.0, 1.3, 1.7, 2.2, 3.0, 4.5, 6.0)


def incidence_of(normalized):
    return float(np.degrees(np.arctan(normalized * 2 * MU)))


def rebound(states, model):
    """(tangential velocity of the first body, its spin times its radius) after the impact; the
    tangent is x against the wall, y for two spheres on the x axis."""
    wall = bool(model.walls)
    return states.velocities[-1, 0, 0 if wall else 1], states.spins[-1, 0] * D / 2


def test_gross_sliding_on_a_wall_in_the_reference_engine():
    """Every RK4 stage slides, F_t = μ F_n, and RK4 combines stages linearly: J_t = μ J_n exactly,
    Δv_t = −μ(1 + e) v_n, ω r = −(5/2) μ (1 + e) v_n."""
    incidence = 80.0
    model = sphere_on_wall(incidence, MU)
    v_n, v_t = V0 * np.cos(np.radians(incidence)), V0 * np.sin(np.radians(incidence))
    states = reference_states(model, impact_settings(model, STEPS), every=STEPS)
    out_t, spin_r = rebound(states, model)
    e = states.velocities[-1, 0, 1] / v_n
    assert e == pytest.approx(1.0, rel=1e-6)
    assert out_t - v_t == pytest.approx(-MU * (1 + e) * v_n, rel=1e-9)
    assert spin_r == pytest.approx(-2.5 * MU * (1 + e) * v_n, rel=1e-9)


def test_reference_engine_follows_hertz_mindlin_on_a_wall_over_the_whole_incidence_range():
    """The tangential impulse against incidence (Maw–Barber–Fawcett's curve), the reference engine
    against the SciPy solution, within the engine's convergence in the time step; and in the
    sticking limit against Mindlin's uncapped contact."""
    for normalized in NORMALIZED_INCIDENCES:
        model = sphere_on_wall(incidence_of(normalized), MU)
        contact, mass = Contact.of(model), model.masses_kg[0]
        v_n, v_t = V0 * np.cos(np.radians(incidence_of(normalized))), V0 * np.sin(np.radians(incidence_of(normalized)))
        impulse, _, _, _ = solve_contact(contact, v_n, v_t)
        moved = [
            mass * (rebound(reference_states(model, impact_settings(model, steps), every=steps), model)[0] - v_t)
            for steps in (STEPS, 2 * STEPS)
        ]
        gross = MU * 2 * mass * v_n
        assert abs(moved[1] - impulse) <= convergence_bound(moved[0], moved[1], gross, STEPS), normalized


@pytest.mark.parametrize("build", [sphere_on_wall, sphere_in_ring, sphere_pair], ids=["wall", "ring", "pair"])
def test_engines_agree_on_rebound_and_spin_over_the_whole_incidence_range(tmp_path, build):
    """LAMMPS against the reference engine, a sphere on a flat wall, inside a curved wall (radius 3 d,
    LAMMPS's contact radius for it, :class:`~hexdem.model.walls.CurvedWall`) and two spheres (whose
    contact turns as they slide, which both engines follow), on the rebound tangential velocity and
    the spin: within the sum of the two engines' convergence bounds."""
    worst = 0.0
    for k, normalized in enumerate(NORMALIZED_INCIDENCES):
        model = build(incidence_of(normalized), MU)
        scale = MU * 2 * V0 * np.cos(np.radians(incidence_of(normalized)))  # μ(1 + e) v_n
        results = {}
        for steps in (STEPS, 2 * STEPS):
            settings = impact_settings(model, steps)
            results["lammps", steps] = rebound(
                lammps_states(model, settings, tmp_path / f"{k}-{steps}", every=settings.n_steps), model
            )
            results["reference", steps] = rebound(reference_states(model, settings, every=settings.n_steps), model)
        for q in range(2):  # tangential velocity, spin
            bound = sum(
                convergence_bound(results[engine, STEPS][q], results[engine, 2 * STEPS][q], scale, STEPS)
                for engine in ("lammps", "reference")
            )
            gap = abs(results["lammps", 2 * STEPS][q] - results["reference", 2 * STEPS][q])
            assert gap <= bound, (normalized, q)
            worst = max(worst, gap / scale)
    assert worst < 1e-3


def test_free_packing_keeps_its_angular_momentum_in_the_reference_engine():
    """No walls: Σ m x × v + I ω about the origin; each force evaluation balances the torques exactly
    (levers R_i − δ/2), so RK4 keeps it to its truncation error, which halving the step shrinks."""
    config = RunConfig(
        shape="sites",
        sites=[[0, 0], [2, 0], [1, 1], [3, 1], [1, -1], [4, 0], [2, 2]],
        impact="striker",
        strike_angle_deg=35.0,
        friction=0.5,
        wall_material="none",
        duration=4e-4,
    )
    model = build_model(config)
    masses, radii = model.masses_kg, model.diameters_m / 2
    drifts = []
    for halving in (1, 2):
        settings = run_settings(config, model)
        settings = type(settings)(settings.dt_s / halving, settings.n_steps * halving, 10 * halving)
        states = reference_states(model, settings, every=10 * halving)
        orbital = masses * (
            states.positions[..., 0] * states.velocities[..., 1] - states.positions[..., 1] * states.velocities[..., 0]
        )
        momentum = orbital.sum(axis=1) + (INERTIA * masses * radii**2 * states.spins).sum(axis=1)
        drifts.append(np.abs(momentum - momentum[0]).max() / (masses.max() * V0 * D))
        assert (INERTIA * masses * radii**2 * np.abs(states.spins)).sum(axis=1).max() > 1e-3 * masses.max() * V0 * D
    assert drifts[1] < drifts[0] / 2 and drifts[1] < 1e-6


def test_frictionless_models_keep_the_frictionless_kernel_and_frictional_ones_spin(tmp_path):
    """The engine picks its kernel from the contact law: a frictionless model runs the kernel of
    before (``reference.json`` counts the pairs of its neighbour list) and its samples carry no spins,
    a frictional one the frictional kernel, whose samples carry the spheres' spins."""
    config = RunConfig(edge_beads=4, impact="striker", strike_angle_deg=20.0, engine="reference")
    for friction, system in ((0.0, ReferenceSystem), (0.4, FrictionalSystem)):
        model = build_model(config.replace(friction=friction))
        samples = []
        engine = ReferenceEngine().run(
            model, run_settings(config, model), tmp_path / str(friction), samples.append, show_progress=False
        )
        assert engine["n_pairs"] == system.from_model(model, SI).pairs.n_pairs
        assert np.isfinite(samples[-1].velocities).all()
        spins = samples[-1].angular_velocities
        assert (spins is None) if friction == 0 else (np.isfinite(spins).all() and np.abs(spins).max() > 0)


@pytest.mark.parametrize("engine", ["reference", "lammps"])
def test_friction_in_the_papers_units_is_the_si_run_rescaled(tmp_path, engine):
    """G* is a stress like E*, so the paper's A = d = M = 1 carry Mindlin's law as they carry Hertz's:
    a frictional run in nondimensional units, rescaled to SI, is the SI run (4 per edge, 20° striker,
    μ = 0.3 against the beads and the walls)."""
    si = RunConfig(edge_beads=4, impact="striker", strike_angle_deg=20.0, friction=0.3, duration=2e-4)
    units = nondimensional(si.diameter_m, STEEL_316)
    scaled = si.replace(units="nondimensional", v0=si.v0 / units.velocity_m_s, duration=si.duration / units.time_s)
    finals = []
    for config in (si, scaled):
        model = build_model(config)
        run = ReferenceEngine() if engine == "reference" else LammpsEngine()
        trajectory = record(run, model, run_settings(config, model), tmp_path / config.units)
        finals.append(trajectory.velocities_m_s[-1])
    assert np.abs(finals[0]).max() > 0.05 * V0
    np.testing.assert_allclose(finals[1], finals[0], rtol=0, atol=1e-8 * V0)


@pytest.mark.parametrize(
    "keys",
    [
        {"edge_beads": 5, "striker_material": "brass", "strike_angle_deg": 15.0},
        {"edge_beads": 4, "strike_angle_deg": 25.0, "sensors": ["0:1", "+30:2"], "sensor_mass_factor": 2.0},
    ],
    ids=["brass-striker", "heavy-sensors"],
)
def test_engines_agree_on_a_frictional_packings_peak_speeds(tmp_path, keys):
    """A hexagon with μ = 0.3 between spheres and against the walls, struck obliquely by a striker
    (of brass; or of steel, with sensor beads twice as heavy, whose I = (2/5) m r² follows their mass):
    every body's peak speed (the largest sampled), LAMMPS against the reference engine, within the sum
    of the engines' changes from 140 to 280 steps per contact (plus their second-order floors): the
    friction's whole network of stick and slip, not one contact. The striker and the sensors turn."""
    base = RunConfig(impact="striker", friction=0.3, **keys)
    peaks = {}
    for steps in (140, 280):
        config = base.replace(steps_per_contact=steps)
        model = build_model(config)
        for name, engine in (("lammps", LammpsEngine()), ("reference", ReferenceEngine())):
            samples = []
            engine.run(
                model, run_settings(config, model), tmp_path / f"{name}-{steps}", samples.append, show_progress=False
            )
            speeds = np.array([np.linalg.norm(s.velocities[np.argsort(s.ids)], axis=1) for s in samples])
            peaks[name, steps] = speeds.max(axis=0)  # by body id
        spins = np.abs([s.angular_velocities for s in samples]).max(axis=0)  # the reference engine's
        assert np.all(spins[[*model.sensor_beads, model.n_bodies - 1]] > 0)
    floor = V0 / 280**2
    bound = sum(np.abs(peaks[name, 140] - peaks[name, 280]) * 2 + floor for name in ("lammps", "reference"))
    gap = np.abs(peaks["lammps", 280] - peaks["reference", 280])
    assert np.all(gap <= bound), (gap / bound).max()
    assert gap.max() < 1e-3 * V0, gap.max()


def test_a_contact_that_opens_and_closes_again_starts_afresh(tmp_path):
    """A sphere in a ring (radius 3 d) struck at 40° with μ = 0.3, followed across the ring through
    three impacts. LAMMPS drops a contact's history when it opens, so each new contact's tangential
    displacement starts from zero: the reference engine's ξ, set to 0 by every step that finds the
    sphere apart from the ring, holds no more than that one step's slip, (|v| + R|ω|) dt, there
    (a history carried across the gap would grow step by step); and the final velocity and spin
    of both engines agree within the sum of their convergence bounds."""
    model = sphere_in_ring(40.0, MU)
    crossing = 15 * D / V0 / impact_settings(model, 1, 1.0).dt_s  # contact times: three impacts
    finals = {}
    for steps in (100, 200):
        settings = impact_settings(model, steps, crossing)
        reference = reference_states(model, settings, every=steps)
        lammps = lammps_states(model, settings, tmp_path / str(steps), every=settings.n_steps)
        for name, states in (("lammps", lammps), ("reference", reference)):
            finals[name, steps] = np.array([*states.velocities[-1, 0], states.spins[-1, 0] * D / 2])
    apart = model.walls[0].gaps_m(reference.positions[:, 0], D / 2) > 0
    history = np.abs(reference.wall_histories[:, 0])
    one_step = (
        np.linalg.norm(reference.velocities[:, 0], axis=1) + D / 2 * np.abs(reference.spins[:, 0])
    ) * settings.dt_s
    changes = np.flatnonzero(np.abs(np.diff(reference.spins[:, 0])) > 1e-6 * np.abs(reference.spins).max())
    assert len(np.unique(changes // 10)) >= 3  # the spin changes at three impacts
    assert (
        apart.sum() > 100 and np.all(history[apart] <= one_step[apart]) and history[~apart].max() > 2 * one_step.max()
    )
    scale = MU * 2 * V0 * np.cos(np.radians(40.0))  # μ(1 + e) v_n of the first impact
    bound = sum(
        convergence_bound(finals[engine, 100], finals[engine, 200], scale, 100) for engine in ("lammps", "reference")
    )
    gap = np.abs(finals["lammps", 200] - finals["reference", 200])
    assert np.all(gap <= bound), gap / bound
