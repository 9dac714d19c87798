"""Oblique impacts for the friction benchmarks of Chung & Ooi, Granular Matter 13, 643 (2011), in 2D:
a sphere on a flat wall and two spheres, built as hexdem models; LAMMPS run on them with the
spins read; and an independent solution of the one-contact Hertz–Mindlin problem.

The independent solution integrates, with SciPy, the contact's relative motion: the overlap δ
and its rate w, F_n = k_n sqrt(R δ) δ, with Tsuji's damping α (Tsuji et al. 1992) F_n =
max(A δ^{3/2} + α sqrt(m_n A) δ^{1/4} w, 0), A = k_n sqrt(R), clipped at zero as it opens;
m_n ẇ = −F_n; the tangential displacement ξ of the contact points, driven by their relative slip
velocity v_c, ξ' = v_c, and F_t = −k_t a ξ with a = sqrt(R δ), capped by Coulomb:
|ξ| ≤ μ F_n/(k_t a) (μ k_n δ/k_t undamped; at the cap, ξ' is the smaller of v_c and the cap's
rate, outwards); v_c' = F_t c(δ) with c the tangential compliance of the bodies at the
contact (1/m + r²/I for a sphere on a wall, I = (2/5) m r²; for two spheres LAMMPS's lever arms
r_i − δ/2, see ``granular_model.cpp``). It returns the tangential impulse J_t = ∫F_t dt and the
rebound rates.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass, replace
from functools import cache

import numpy as np
from conftest import V0, D, single_bead

from hexdem.engines.lammps.deck import write_deck
from hexdem.engines.lammps.driver import in_folder, split_deck
from hexdem.engines.lammps.library import load_lammps
from hexdem.engines.reference.friction import FrictionalSystem
from hexdem.model.contact_law import Friction
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.hertz import contact_time
from hexdem.model.materials import DELRIN, STEEL_316
from hexdem.model.packing import Packing
from hexdem.model.units import SI
from hexdem.model.walls import CurvedWall, Wall

#: Lever and inertia of a solid sphere: I = INERTIA m r².
INERTIA = 0.4


def sphere_on_wall(incidence_deg: float, friction: float, speed: float = V0) -> GranularModel:
    """A steel sphere touching a delrin-lined flat wall (inward normal +y) at t = 0, moving into it
    at ``speed`` at ``incidence_deg`` from the normal: v = V (sin θ, −cos θ)."""
    wall = Wall("wall_090", (0.0, 1.0), -D / 2, np.array([0]))
    return GranularModel(
        replace(single_bead(D), walls=(wall,)),
        Impact(speed, incidence_deg - 90.0, bead=0),
        STEEL_316,
        DELRIN,
        friction=Friction(friction, friction),
    )


def sphere_in_ring(incidence_deg: float, friction: float, ring_radius_d: float = 3.0) -> GranularModel:
    """As :func:`sphere_on_wall`, inside a curved (cylindrical) wall of radius ``ring_radius_d`` d
    touching the sphere from below."""
    ring = CurvedWall("ring", (0.0, (ring_radius_d - 0.5) * D), ring_radius_d * D, np.array([0]))
    return replace(sphere_on_wall(incidence_deg, friction), packing=replace(single_bead(D), walls=(ring,)))


def sphere_pair(incidence_deg: float, friction: float, speed: float = V0) -> GranularModel:
    """Two touching steel spheres on the x axis; the first moves at ``speed`` at ``incidence_deg`` from
    the line of centres towards the second, at rest."""
    lattice = Packing(np.array([[0, 0], [2, 0]]), np.array([[0.0, 0.0], [D, 0.0]]), np.full(2, D), D, 0, (), "pair")
    return GranularModel(
        lattice, Impact(speed, incidence_deg, bead=0), STEEL_316, None, friction=Friction(friction, friction)
    )


@dataclass(frozen=True)
class Contact:
    """One contact's parameters for :func:`solve_contact`: Hertz k_n and Mindlin k_t [Pa], R_eff [m],
    μ, normal mass m_n [kg], the bodies' radii, masses, whether the contact is with a wall, and Tsuji's
    damping α."""

    k_n: float
    k_t: float
    r_eff: float
    mu: float
    m_n: float
    radii: tuple
    masses: tuple
    wall: bool
    damping: float = 0.0

    @classmethod
    def of(cls, model: GranularModel) -> Contact:
        masses, radii = tuple(model.masses_kg), tuple(model.diameters_m / 2)
        if model.walls:
            law = model.laws.walls[0]
            return cls(
                law.normal_stiffness_pa,
                law.tangential_stiffness_pa,
                radii[0],
                law.friction,
                masses[0],
                radii,
                masses,
                True,
                law.damping,
            )
        law = model.laws.pairs[0][0]
        return cls(
            law.normal_stiffness_pa,
            law.tangential_stiffness_pa,
            radii[0] * radii[1] / (radii[0] + radii[1]),
            law.friction,
            masses[0] * masses[1] / (masses[0] + masses[1]),
            radii,
            masses,
            False,
            law.damping,
        )

    def compliance(self, overlap: float) -> float:
        """dv_c/dF_t: 1/m + r²/I against a wall (LAMMPS's lever r), Σ 1/m_i + r_i (r_i − δ/2)/I_i for two
        spheres (LAMMPS's levers r_i − δ/2, its slip velocity with r_i)."""
        if self.wall:
            return 1 / self.masses[0] + 1 / (INERTIA * self.masses[0])
        (m0, m1), (r0, r1) = self.masses, self.radii
        return 1 / m0 + 1 / m1 + (r0 - overlap / 2) / (INERTIA * m0 * r0) + (r1 - overlap / 2) / (INERTIA * m1 * r1)

    def contact_time(self, normal_speed: float) -> float:
        return float(contact_time(self.m_n, self.k_n * np.sqrt(self.r_eff), normal_speed))


@cache
def solve_contact(contact: Contact, normal_speed: float, slip_speed: float, capped: bool = True, steps: int = 1000):
    """(J_t, rebound normal rate −w_out, slip velocity v_c,out, max |F_t|/F_n) of one contact struck at
    ``normal_speed`` with the contact points slipping at ``slip_speed``; ``capped`` False: no Coulomb
    cap (Mindlin's no-slip contact throughout); steps of at most τ/``steps``."""
    from scipy.integrate import solve_ivp

    c = contact
    stiffness = c.k_n * math.sqrt(c.r_eff)
    eta = c.damping * math.sqrt(c.m_n * stiffness)
    per_force = c.mu / (c.k_t * math.sqrt(c.r_eff))  # the cap on ξ per unit F_n/sqrt(δ)

    def normal(overlap, rate):
        return max(stiffness * overlap**1.5 + eta * overlap**0.25 * rate, 0.0)

    def limit(overlap, rate):
        """The cap on |ξ|, μ F_n/(k_t a) (none before the bodies touch)."""
        return per_force * normal(overlap, rate) / math.sqrt(overlap) if capped and overlap > 0 else math.inf

    def limit_rate(overlap, rate):
        """d/dt of :func:`limit` (0 where the clipped F_n is 0)."""
        force = normal(overlap, rate)
        if force == 0.0:
            return 0.0
        force_rate = 1.5 * stiffness * math.sqrt(overlap) * rate + eta * (
            0.25 * overlap**-0.75 * rate**2 - overlap**0.25 * force / c.m_n
        )
        return per_force * (force_rate / math.sqrt(overlap) - 0.5 * force * rate / overlap**1.5)

    def rhs(t, y):
        overlap, rate, xi, slip, impulse = y
        overlap = max(overlap, 0.0)
        bound = limit(overlap, rate)
        force = -c.k_t * math.sqrt(c.r_eff * overlap) * min(max(xi, -bound), bound)
        if abs(xi) < bound:
            growth = slip
        else:  # at the cap: ξ moves with the contact points only as far as the cap lets it
            sign = 1.0 if xi > 0 else -1.0
            growth = sign * min(sign * slip, limit_rate(overlap, rate))
        return [rate, -normal(overlap, rate) / c.m_n, growth, force * c.compliance(overlap), force]

    def separated(t, y):
        return y[0]

    separated.terminal, separated.direction = True, -1
    tau = c.contact_time(normal_speed)
    solution = solve_ivp(
        rhs,
        (0.0, 2 * tau),
        [0.0, normal_speed, 0.0, slip_speed, 0.0],
        method="DOP853",
        events=separated,
        rtol=1e-11,
        atol=1e-16,
        max_step=tau / steps,
        dense_output=True,
    )
    end = solution.y_events[0][0]
    samples = solution.sol(np.linspace(0, solution.t_events[0][0], 2001)[1:-1]).T
    ratios = [
        c.k_t * math.sqrt(c.r_eff * overlap) * min(limit(overlap, rate), abs(xi)) / normal(overlap, rate)
        for overlap, rate, xi, _, _ in samples
        if normal(overlap, rate) > 0
    ]
    return end[4], -end[1], end[3], float(max(ratios))


@dataclass(frozen=True)
class States:
    """Recorded states (SI): ``times`` (T,), ``positions``, ``velocities`` (T, N, 2), ``spins`` ω_z (T, N),
    from LAMMPS ``forces`` (T, N, 2), from the reference engine the wall contacts' ``wall_histories``
    ξ (T, K) [m] as integrated (before the step that follows sets them back to the Coulomb cap)."""

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    spins: np.ndarray
    forces: np.ndarray | None = None
    wall_histories: np.ndarray | None = None


@contextmanager
def lammps_deck(model: GranularModel, settings: RunSettings, directory):
    """A LAMMPS instance set up from hexdem's deck of ``model`` (its commands up to the output section)."""
    deck = write_deck(model, settings, directory)
    lmp = load_lammps().lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    try:
        lmp.commands_string(in_folder(split_deck(deck.input_path.read_text())[0], directory))
        yield lmp
    finally:
        lmp.close()


def lammps_states(model: GranularModel, settings: RunSettings, directory, every: int = 1) -> States:
    """Run ``model`` in LAMMPS through hexdem's deck, recording every ``every`` steps (SI settings)."""
    records = []

    def record(lmp):
        order = np.argsort(lmp.numpy.extract_atom("id"))
        records.append([np.array(lmp.numpy.extract_atom(name))[order] for name in ("x", "v", "omega", "f")])

    with lammps_deck(model, settings, directory) as lmp:
        lmp.command("run 0")
        record(lmp)
        for _ in range(settings.n_steps // every):
            lmp.command(f"run {every} pre no post no")
            record(lmp)
    x, v, omega, f = (np.array(values) for values in zip(*records))
    times = np.arange(len(records)) * every * settings.dt_s
    return States(times, x[..., :2], v[..., :2], omega[..., 2], f[..., :2])


def reference_states(model: GranularModel, settings: RunSettings, every: int = 1) -> States:
    """Run ``model`` in the reference integrator's frictional system (SI settings), recording every
    ``every`` steps."""
    system = FrictionalSystem.from_model(model, SI)
    start, records = model.initial_positions_m(), []

    def emit(index, step, x, y, u, w):
        records.append(
            (
                step * settings.dt_s,
                start + np.column_stack([x, y]),
                np.column_stack([u, w]),
                system.state["spins"].copy(),
                system.state["wall_xi"] * SI.length_m,
            )
        )

    system.integrate(model.initial_velocities_m_s(), settings.dt_s, replace(settings, dump_every=every), emit)
    times, positions, velocities, spins, histories = (np.array(values) for values in zip(*records))
    return States(times, positions, velocities, spins, wall_histories=histories)


def convergence_bound(coarse, fine, scale, steps):
    """How far an engine's result ``fine`` at τ/(2 ``steps``) may lie from the exact one: twice its
    change from ``coarse`` at τ/``steps`` (its error at τ/2N is at most that for any order ≥ 1, where
    it converges steadily), but at least a second-order error ``scale``/(2N)², which a stick–slip
    transition falling between steps can leave unshrunk by the halving."""
    return 2 * abs(coarse - fine) + scale / (2 * steps) ** 2


def impact_settings(model: GranularModel, steps_per_contact: int, contacts: float = 1.3) -> RunSettings:
    """Steps of τ/``steps_per_contact`` over ``contacts`` contact times τ of the model's first contact."""
    contact = Contact.of(model)
    normal = model.impact.speed_m_s * abs(model.impact.direction[1] if contact.wall else model.impact.direction[0])
    dt = contact.contact_time(normal) / steps_per_contact
    return RunSettings(dt, int(contacts * steps_per_contact), 1)
