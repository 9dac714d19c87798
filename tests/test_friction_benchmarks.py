"""LAMMPS with friction, through hexdem's decks, on the benchmarks of Chung & Ooi, Granular Matter 13,
643 (2011) that apply in 2D: normal impact (Hertz), oblique impacts of a sphere on a wall and of two
spheres over the whole range of incidence, elastic and damped (e < 1: Tsuji's damping, its normal force
clipped at zero, :mod:`hexdem.model.dissipation`); and angular momentum in a free packing.

Every figure is derived: the Hertz contact time (:mod:`hexdem.model.hertz`); in gross sliding the
tangential impulse is μ times the normal one, so a sphere leaving a wall has Δv_t = −μ(1 + e) v_n and
ω r = (5/2) μ (1 + e) v_n (I = (2/5) m r²), for a damped contact too as long as its normal force never
pulls (then ∫|F_n| dt = ∫F_n dt = m (1 + e) v_n); otherwise the SciPy solution of the one-contact
Hertz–Mindlin problem (``oblique.solve_contact``; without its Coulomb cap for the sticking limit).
Tolerances come from LAMMPS's own convergence in the time step: its result at τ/N and τ/2N differ by
at least half its error at τ/2N for any order ≥ 1, so the answer at τ/2N must lie within
2 |r(τ/N) − r(τ/2N)| (plus round-off) of the exact one.
"""

from dataclasses import replace

import numpy as np
import pytest
from conftest import V0, D
from oblique import (
    INERTIA,
    Contact,
    convergence_bound,
    impact_settings,
    lammps_deck,
    lammps_states,
    reference_states,
    solve_contact,
    sphere_on_wall,
    sphere_pair,
)

from hexdem.analysis.peaks import refine_peak
from hexdem.model.config import RunConfig
from hexdem.model.granular import RunSettings
from hexdem.model.materials import STEEL_316
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

MU = 0.3
#: Round-off floor of a rebound velocity compared with an exact one, relative to V0.
ROUND_OFF = 1e-9
STEPS = 400


def components(model, incidence_deg):
    """(normal, tangential) speed of the impact at ``incidence_deg``."""
    return model.impact.speed_m_s * np.cos(np.radians(incidence_deg)), model.impact.speed_m_s * np.sin(
        np.radians(incidence_deg)
    )


def wall_rebound(model, directory, steps=STEPS):
    """(v_t, v_n, ω r) of the sphere after it left the wall, LAMMPS at τ/``steps``."""
    settings = impact_settings(model, steps)
    states = lammps_states(model, settings, directory, every=settings.n_steps)
    (v_t, v_n), spin = states.velocities[-1, 0], states.spins[-1, 0]
    return np.array([v_t, v_n, spin * D / 2])


def test_lammps_multiplies_the_mindlin_stiffness_by_the_contact_radius(tmp_path):
    """One step from an overlap δ with a tangential speed u and no history: LAMMPS's history is then
    ξ = u dt (the step's half-step slip, no torque at set-up), so F_t = −k_t a u dt with
    a = sqrt(R_eff δ) at the step's overlap; for a wall and for a pair alike."""
    dt, u, overlap = 1e-8, 0.1, 2e-6
    for name, model in (("wall", sphere_on_wall(90.0, 10.0, speed=u)), ("pair", sphere_pair(90.0, 10.0, speed=u))):
        contact = Contact.of(model)
        shifted = model.packing.positions_m.copy()
        shifted[0] += (0.0, -overlap) if contact.wall else (overlap, 0.0)
        lattice = replace(model.packing, positions_m=shifted)  # the walls stay
        with lammps_deck(replace(model, packing=lattice), RunSettings(dt, 1, 1), tmp_path / name) as lmp:
            lmp.command("run 1")
            order = np.argsort(lmp.numpy.extract_atom("id"))
            x = np.array(lmp.numpy.extract_atom("x"))[order, :2]
            force = np.array(lmp.numpy.extract_atom("f"))[order, :2]
        offset = x[1] - x[0] if not contact.wall else np.array([0.0, 1.0])  # the wall's normal: +y
        normal = offset / np.linalg.norm(offset)
        step_overlap = -x[0, 1] if contact.wall else D - np.linalg.norm(offset)  # the wall's surface is y = −D/2
        tangent = np.array([-normal[1], normal[0]])
        tangential = force[0] @ (tangent * np.sign(tangent @ model.impact.direction))  # along the sphere's motion
        expected = -contact.k_t * np.sqrt(contact.r_eff * step_overlap) * u * dt
        assert tangential == pytest.approx(expected, rel=1e-9), name


def test_normal_impact_with_friction_is_hertz_and_does_not_spin(tmp_path):
    model = sphere_on_wall(0.0, MU)
    contact = Contact.of(model)
    settings = impact_settings(model, STEPS)
    states = lammps_states(model, settings, tmp_path)
    depth = -states.positions[:, 0, 1]
    k = int(np.flatnonzero(depth[1:] < 0)[0]) + 1
    duration = np.interp(0.0, depth[[k, k - 1]], states.times[[k, k - 1]])
    assert duration == pytest.approx(contact.contact_time(V0), rel=1e-4)
    assert refine_peak(states.times, depth)[1] > 0
    assert states.velocities[-1, 0, 1] == pytest.approx(V0, rel=1e-6)  # e = 1: elastic
    assert (
        np.abs(states.spins).max() * D / 2 < ROUND_OFF * V0
        and np.abs(states.velocities[:, 0, 0]).max() < ROUND_OFF * V0
    )


@pytest.mark.parametrize("incidence_deg", [75.0, 85.0])
def test_gross_sliding_on_a_wall_gives_mu_times_the_normal_impulse(tmp_path, incidence_deg):
    """tan θ > (7/2) μ (1 + e): the contact slides throughout, J_t = μ J_n = μ m (1 + e) v_n."""
    model = sphere_on_wall(incidence_deg, MU)
    v_n, v_t = components(model, incidence_deg)
    assert v_t / v_n > 3.5 * MU * 2
    out_t, out_n, spin_r = wall_rebound(model, tmp_path)
    e = out_n / v_n
    assert e == pytest.approx(1.0, rel=1e-6)
    assert out_t - v_t == pytest.approx(-MU * (1 + e) * v_n, rel=1e-6)
    assert -spin_r == pytest.approx(2.5 * MU * (1 + e) * v_n, rel=1e-6)


def start_of_sliding_deficit(contact, v_n, v_t, restitution):
    """An upper bound on how far a damped contact's tangential impulse falls short of μ J_n, relative to
    μ m (1 + e) v_n: at the contact's start Tsuji's damping gives F_n ≈ η (v_n t)^{1/4} v_n, which
    outgrows Mindlin's F_t ≈ k_t sqrt(R v_n t) v_t t (δ ≈ v_n t, the contact points slipping at v_t) until
    t_s where F_t = μ F_n; before t_s, 0 < μ F_n − F_t < μ F_n, so the shortfall is below μ ∫₀^{t_s} F_n dt."""
    from scipy.optimize import brentq

    stiffness = contact.k_n * np.sqrt(contact.r_eff)
    eta = contact.damping * np.sqrt(contact.m_n * stiffness)

    def normal(t):
        return stiffness * (v_n * t) ** 1.5 + eta * (v_n * t) ** 0.25 * v_n

    start = brentq(
        lambda t: contact.k_t * np.sqrt(contact.r_eff * v_n * t) * v_t * t - contact.mu * normal(t),
        1e-15 * contact.contact_time(v_n),
        contact.contact_time(v_n),
    )
    impulse = stiffness * v_n**1.5 * 0.4 * start**2.5 + eta * v_n**1.25 * 0.8 * start**1.25  # ∫₀^{t_s} F_n dt
    return impulse / (contact.m_n * (1 + restitution) * v_n)


def test_a_sphere_sliding_on_a_damped_wall_spins_as_the_rigid_body_law(tmp_path):
    """Steel on steel, μ = 0.1, 60° (gross sliding: tan θ > (7/2) μ (1 + e)), e = 0.8. The clipped
    normal force never pulls, so |F_t| ≤ μ F_n gives ω r ≤ (5/2) μ (1 + e) v_n; the contact sticks only
    at its very start, which costs at most :func:`start_of_sliding_deficit` (6e-4 here). Measured: ω r
    3.0e-4 below the law in both engines (the SciPy solution: 3.01e-4); without the clip 0.87 % above
    it, the cap μ |F_n| acting on the pulling force too."""
    incidence, e, mu = 60.0, 0.8, 0.1
    model = replace(sphere_on_wall(incidence, mu), wall=STEEL_316, wall_restitution=e)
    v_n, v_t = components(model, incidence)
    assert v_t / v_n > 3.5 * mu * (1 + e)
    rigid = 2.5 * mu * (1 + e) * v_n
    deficit = start_of_sliding_deficit(Contact.of(model), v_n, v_t, e)
    assert deficit < 1e-3
    for name in ("lammps", "reference"):
        spins, slides = [], []
        for steps in (800, 1600):
            settings = impact_settings(model, steps)
            states = (
                lammps_states(model, settings, tmp_path / f"{name}{steps}", every=settings.n_steps)
                if name == "lammps"
                else reference_states(model, settings, every=settings.n_steps)
            )
            spins.append(-states.spins[-1, 0] * D / 2)
            slides.append(v_t - states.velocities[-1, 0, 0])
        for measured, law in ((spins, rigid), (slides, rigid / 2.5)):  # ω r and −Δv_t = μ (1 + e) v_n
            bound = convergence_bound(measured[0], measured[1], law, 800)
            assert law * (1 - deficit) - bound <= measured[1] <= law + bound, (name, measured[1] / law - 1)


def contact_impulses(states, first, second):
    """(J_n, J_t) on body ``second`` from body ``first`` in the turning contact frame, n from first to
    second, t = ẑ × n: velocity Verlet's kicks add the forces of successive steps with weights dt/2,
    so the trapezoid sum of the recorded forces, each split along its own step's normal, is the
    impulse LAMMPS applied."""
    offset = states.positions[:, second] - states.positions[:, first]
    normal = offset / np.linalg.norm(offset, axis=1)[:, None]
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    force = states.forces[:, second]
    dt = np.diff(states.times)
    pieces = [np.einsum("ij,ij->i", force, axis) for axis in (normal, tangent)]
    return tuple(float(np.sum(dt * (p[1:] + p[:-1]) / 2)) for p in pieces)


def test_gross_sliding_of_two_spheres_gives_mu_times_the_normal_impulse(tmp_path):
    """Two equal spheres, one at rest, at grazing incidence: the contact slides throughout, so the
    tangential impulse in the contact's (turning) frame is μ times the normal one; momentum is kept
    and both spheres spin alike."""
    model = sphere_pair(80.0, MU)
    settings = impact_settings(model, STEPS)
    states = lammps_states(model, settings, tmp_path)
    normal, tangential = contact_impulses(states, 0, 1)
    assert normal > 0 and tangential == pytest.approx(MU * normal, rel=1e-9)  # the first drags the second along
    momentum = np.einsum("i,tij->tj", model.masses_kg, states.velocities)
    np.testing.assert_allclose(momentum, momentum[[0]].repeat(len(momentum), axis=0), rtol=1e-12)
    w0, w1 = states.spins[-1]
    assert w0 == pytest.approx(w1, rel=1e-12) and w0 < 0


def test_small_incidence_sticks_as_mindlins_no_slip_contact(tmp_path):
    """At tan θ ≪ μ the Coulomb cap hardly acts: the contact points' slip velocity comes back as
    Mindlin's uncapped spring gives it, v_c,out/v_c,in a fixed ratio set by k_t/k_n and the sphere's
    inertia alone (here it differs from both gross sliding and rolling, v_c,out = 0)."""
    incidence = np.degrees(np.arctan(0.01 * MU))
    model = sphere_on_wall(incidence, MU)
    v_n, v_t = components(model, incidence)
    ratios = []
    for steps in (STEPS, 2 * STEPS):
        out_t, _, spin_r = wall_rebound(model, tmp_path / str(steps), steps)
        ratios.append((out_t + spin_r) / v_t)  # the contact point's velocity v_t + ω r
    _, _, slip, _ = solve_contact(Contact.of(model), v_n, v_t, capped=False)
    _, _, capped, _ = solve_contact(Contact.of(model), v_n, v_t)
    assert capped / v_t == pytest.approx(slip / v_t, abs=1e-3)  # the cap acts only in the last instants
    assert abs(slip / v_t) > 0.1 and abs(slip / v_t - (1 - 3.5 * MU * 2 * v_n / v_t)) > 0.1
    assert abs(ratios[1] - slip / v_t) <= convergence_bound(ratios[0], ratios[1], 1.0, STEPS)


#: Incidences of the rebound curves: tan θ / (μ(1 + e)) from 0.05 (sticking) to 6 (gross sliding).
NORMALIZED_INCIDENCES = (0.05, 0.2, 0.5, 0.8, 1.0, 1.3, 1.7, 2.2, 3.0, 4.5, 6.0)


@pytest.mark.parametrize("restitution", [1.0, 0.8])
def test_rebound_curve_on_a_wall_over_the_whole_incidence_range_matches_hertz_mindlin(tmp_path, restitution):
    """Maw–Barber–Fawcett's curve: the tangential impulse against incidence, LAMMPS against the SciPy
    solution of the same contact law, within LAMMPS's convergence in the time step: elastic, and damped
    to e = 0.8 (Chung & Ooi's oblique impacts at one speed over the incidence range, with e < 1), the
    SciPy solution's normal force clipped at zero as LAMMPS's ``limit_damping`` clips it. (Two spheres
    turn their contact as they slide past each other, which the one-contact solution leaves out;
    the engines are compared with each other there, in tests/test_friction_engines.py.)"""
    worst = 0.0
    for k, normalized in enumerate(NORMALIZED_INCIDENCES):
        incidence = np.degrees(np.arctan(normalized * (1 + restitution) * MU))
        model = replace(sphere_on_wall(incidence, MU), wall_restitution=restitution)
        contact = Contact.of(model)
        v_n, v_t = components(model, incidence)
        impulse, _, _, _ = solve_contact(contact, v_n, v_t)
        moved = []
        for steps in (STEPS, 2 * STEPS):
            settings = impact_settings(model, steps)
            states = lammps_states(model, settings, tmp_path / f"{k}-{steps}", every=settings.n_steps)
            moved.append(model.masses_kg[0] * (states.velocities[-1, 0, 0] - v_t))
        gross = MU * (1 + restitution) * contact.m_n * v_n  # the gross-sliding impulse, μ(1 + e) m v_n
        error = abs(moved[1] - impulse)
        assert error <= convergence_bound(moved[0], moved[1], gross, STEPS), normalized
        worst = max(worst, error / gross)
    # of the gross-sliding impulse; with damping, plus a first-order α/N of LAMMPS's half-step damping force
    assert worst < 1e-4 + contact.damping / (2 * STEPS)


def test_free_packing_with_friction_keeps_its_angular_momentum(tmp_path):
    """No walls: Σ m x × v + I ω about the origin is kept (LAMMPS's lever arms r_i − δ/2 add up to
    the distance of the centres, so contact torques balance the forces' moments exactly, and velocity
    Verlet keeps it to round-off)."""
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
    states = lammps_states(model, run_settings(config, model), tmp_path, every=20)
    masses, radii = model.masses_kg, model.diameters_m / 2
    orbital = masses * (
        states.positions[..., 0] * states.velocities[..., 1] - states.positions[..., 1] * states.velocities[..., 0]
    )
    momentum = orbital.sum(axis=1) + (INERTIA * masses * radii**2 * states.spins).sum(axis=1)
    spin = (INERTIA * masses * radii**2 * np.abs(states.spins)).sum(axis=1).max()
    scale = masses.max() * V0 * D
    assert spin > 1e-3 * scale  # the beads turn
    np.testing.assert_allclose(momentum, momentum[0], rtol=0, atol=1e-10 * scale)
