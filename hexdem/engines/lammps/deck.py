r"""Render a :class:`~hexdem.model.granular.GranularModel` into a standalone LAMMPS run directory.

The directory holds ``data.hexdem`` (atoms: id type diameter density x y z) and
``in.hexdem`` (from ``lammps_inputs/impact.in``); ``cd DIR && lmp -in in.hexdem`` reruns it
by hand. Quantities are written in the chosen :class:`~hexdem.model.units.UnitSystem`: SI
(``units si``) or the paper's A = d = M = 1 (``units lj``). Contacts use the ``hertz k_n``
model, :math:`F = k_n \sqrt{R_\text{eff}\, δ}\, δ`, for bead pairs and for the walls alike, so the walls carry
their own modulus (the wall fix's ``hertz/material`` cannot mix materials, LAMMPS issue 4141);
Tsuji's damping with ``limit_damping`` (the normal force clipped at zero); with friction,
Mindlin's ``tangential mindlin`` with each contact's own k_t = 8 G* (given, as LAMMPS cannot
derive it from ``hertz k_n``), and ``fix nve/sphere`` turns the spheres.
An optional uniform in-plane gravity (the tilted set-up of Sec. VI-A) adds ``fix gravity``.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from string import Template

import numpy as np

from hexdem.common.io import text_columns
from hexdem.errors import HexdemError
from hexdem.model.contact_law import ContactLaw
from hexdem.model.dissipation import lammps_tsuji_coefficient
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.units import UnitSystem
from hexdem.model.walls import CurvedWall

DECK_NAME = "in.hexdem"
DATA_NAME = "data.hexdem"
DUMP_NAME = "dump.lammpstrj"
#: LAMMPS holds at most this many groups, ``all`` included (the walls take one per wall and
#: material touching it, the impacts one per distinct velocity, a held bead one).
MAX_GROUPS = 32


@dataclass(frozen=True)
class Deck:
    """A rendered run directory: where its input, data and dump files are."""

    directory: Path
    settings: RunSettings
    n_atoms: int

    @property
    def input_path(self) -> Path:
        return self.directory / DECK_NAME

    @property
    def log_path(self) -> Path:
        return self.directory / "log.lammps"


def _fmt(value: float) -> str:
    return repr(float(value))


def _striker_type_materials(model: GranularModel) -> list[int]:
    """The material ids of the strikers' atom types: one per material the strikers are of, in
    order of first use (one type, of the beads' material, when there is no striker)."""
    return list(dict.fromkeys(model.material_ids[len(model.packing) :].tolist())) or [0]


def atom_types(model: GranularModel) -> np.ndarray:
    """(n_bodies,) LAMMPS atom type of each body: a bead's material id + 1, then the strikers'
    own types (2 for the paper's one material)."""
    first = 2 + len(model.extra_materials)
    striker_type = {material: first + k for k, material in enumerate(_striker_type_materials(model))}
    strikers = [striker_type[m] for m in model.material_ids[len(model.packing) :].tolist()]
    return np.append(model.packing.material_ids + 1, np.array(strikers, dtype=int))


def type_materials(model: GranularModel) -> list[int]:
    """The material id (index into ``model.materials``) of each LAMMPS atom type, 1, 2, …"""
    return [*range(1 + len(model.extra_materials)), *_striker_type_materials(model)]


def data_file(model: GranularModel, units: UnitSystem) -> str:
    """The text of ``data.hexdem``: every body of ``model`` at its initial position, and, with an
    initial state (:mod:`hexdem.model.initial_state`), every body's initial velocity (the
    impacts' ``velocity`` commands then set their bodies to the same sums)."""
    pos = model.initial_positions_m() / units.length_m
    diam = model.diameters_m / units.length_m
    densities = model.densities_kg_m3 * model.mass_factors / units.density_kg_m3
    margin = 2.0 * diam.max()
    lo, hi = pos.min(axis=0) - margin, pos.max(axis=0) + margin
    types = atom_types(model)
    lines = [
        f"hexdem data file: {model.packing.shape}",
        "",
        f"{model.n_bodies} atoms",
        f"{len(type_materials(model))} atom types",
        "",
        f"{_fmt(lo[0])} {_fmt(hi[0])} xlo xhi",
        f"{_fmt(lo[1])} {_fmt(hi[1])} ylo yhi",
        f"{_fmt(-diam.max())} {_fmt(diam.max())} zlo zhi",
        "",
        "Atoms # sphere",
        "",
    ]
    ids = [str(i + 1) for i in range(model.n_bodies)]
    lines += [
        f"{row} 0.0" for row in map(" ".join, zip(ids, *text_columns([types, diam, densities, pos[:, 0], pos[:, 1]])))
    ]
    if model.initial_state is not None:
        velocities = model.initial_velocities_m_s() / units.velocity_m_s
        lines += ["", "Velocities", ""]
        lines += [f"{row} 0.0 0.0 0.0 0.0" for row in map(" ".join, zip(ids, *text_columns(velocities.T)))]
    return "\n".join(lines) + "\n"


#: A curved wall's cylinder reaches this many bead diameters above and below the plane (LAMMPS
#: takes no INF there), so that its end caps never touch a bead.
CYLINDER_HALF_HEIGHT_D = 1000.0


def walls_block(model: GranularModel, units: UnitSystem) -> str:
    """Deck commands for the walls of ``model``: member group, region (a plane, or a cylinder for a
    curved wall) and wall fix each, with the contact law of each material against the wall."""
    if not model.walls:
        return "# (no walls)\n"
    block, laws = [], model.laws.walls
    for wall in model.walls:
        if isinstance(wall, CurvedWall):  # its Hertz law: LAMMPS's own contact radius of a cylinder
            centre = np.asarray(wall.centre_m) / units.length_m
            height = CYLINDER_HALF_HEIGHT_D * model.packing.diameter_m / units.length_m  # the 2D beads at z = 0
            region = (
                f"cylinder z {_fmt(centre[0])} {_fmt(centre[1])} {_fmt(wall.radius_m / units.length_m)} "
                f"{_fmt(-height)} {_fmt(height)} side in"
            )
        else:
            point = np.asarray(wall.normal) * wall.offset_m / units.length_m
            region = (
                f"plane {_fmt(point[0])} {_fmt(point[1])} 0.0 {_fmt(wall.normal[0])} {_fmt(wall.normal[1])} 0.0 side in"
            )
        groups, fixes = [], []
        materials = model.material_ids[wall.members]
        for material in np.unique(materials):  # one fix per material touching the wall: its own law
            members = wall.members[materials == material]
            group = wall.name if len(np.unique(materials)) == 1 else f"{wall.name}_{model.materials[material].name}"
            groups.append(f"group           {group} id {' '.join(str(i + 1) for i in members)}")
            fixes.append(
                f"fix             {group} {group} wall/gran/region granular "
                f"{contact_model(laws[material], units)} region {wall.name}"
            )
        block += [*groups, f"region          {wall.name} {region}", *fixes]
    return "\n".join(block) + "\n"


def template(name: str) -> Template:
    """The deck template ``lammps_inputs/<name>`` shipped with hexdem."""
    return Template(resources.files("hexdem.lammps_inputs").joinpath(name).read_text())


def damping_model(alpha: float) -> str:
    """The damping of a ``hertz`` contact: none (α = 0), or Tsuji's with damping α
    (:mod:`hexdem.model.dissipation`), as LAMMPS's ``damp`` value and model name, with
    ``limit_damping``: the damped normal force clipped at zero, so that it never pulls as the
    contact opens (nor lets the Coulomb cap act there). ``pair_coeff`` and the wall fixes read it
    alike among the sub-models."""
    if alpha == 0.0:
        return "0.0 damping viscoelastic"
    return f"{_fmt(lammps_tsuji_coefficient(alpha))} damping tsuji limit_damping"


def contact_model(law: ContactLaw, units: UnitSystem) -> str:
    """A :class:`~hexdem.model.contact_law.ContactLaw` as LAMMPS's granular sub-models: ``hertz k_n``
    with its damping, and ``tangential mindlin k_t 0 μ`` (k_t = 8 G*, which LAMMPS multiplies by the
    contact radius a; no tangential damping), or no tangential force (``linear_nohistory 0 0``)."""
    normal = f"hertz {_fmt(law.normal_stiffness_pa / units.stress_pa)} {damping_model(law.damping)}"
    if not law.tangential:
        return f"{normal} tangential linear_nohistory 0.0 0.0"
    return f"{normal} tangential mindlin {_fmt(law.tangential_stiffness_pa / units.stress_pa)} 0.0 {_fmt(law.friction)}"


def pair_block(model: GranularModel, units: UnitSystem) -> str:
    r"""The contacts of ``model``'s bodies: ``pair_style granular`` with each pair of atom types'
    own law (:func:`contact_model`: :math:`k_n = \tfrac{4}{3} E^*`,
    :math:`F = k_n \sqrt{R_\text{eff}}\, δ^{3/2}`, and with friction Mindlin's
    :math:`k_t = 8 G^*`), one ``pair_coeff * *`` for one material.

    A frictionless elastic contact of one material is rendered as ``pair_style gran/hertz/history
    k_n NULL 0 NULL 0 0``: with no damping and a friction coefficient of 0 its normal force is the
    same expression as ``pair_style granular``'s ``hertz`` and its tangential force is exactly
    zero, and it costs about a third less per step (``tests/test_pair_styles.py`` shows the forces
    equal to round-off)."""
    laws, kinds = model.laws, type_materials(model)
    law = laws.pairs[int(model.material_ids[0])][int(model.material_ids[0])]
    if model.uniform_contacts and law.damping == 0.0 and not laws.tangential:
        return (
            f"pair_style      gran/hertz/history {_fmt(law.normal_stiffness_pa / units.stress_pa)} NULL 0.0 NULL 0.0 0"
            "\npair_coeff      * *"
        )
    if model.uniform_contacts:
        return f"pair_style      granular\npair_coeff      * * {contact_model(law, units)}"
    lines = ["pair_style      granular"]  # unlike materials: each pair of atom types its own law
    for a in range(len(kinds)):
        for b in range(a, len(kinds)):
            lines.append(f"pair_coeff      {a + 1} {b + 1} {contact_model(laws.pairs[kinds[a]][kinds[b]], units)}")
    return "\n".join(lines)


def granular_block(model: GranularModel, units: UnitSystem) -> str:
    """Deck commands shared by every hexdem deck: 2D sphere atoms from ``data.hexdem`` and
    the contacts of ``model`` (:func:`pair_block`)."""
    friction = model.friction
    return template("granular.in").substitute(
        lammps_units=units.lammps_units,
        pair=pair_block(model, units),
        damping_note="undamped" if model.restitution == 1.0 else f"Tsuji damping, restitution {model.restitution}",
        tangential_note=(
            f"Mindlin tangential force, mu = {friction.friction} (walls {friction.wall_friction})"
            if model.laws.tangential
            else "no tangential force"
        ),
        skin=_fmt(0.1 * model.packing.diameter_m / units.length_m),
    )


def integrator(model: GranularModel) -> str:
    """``fix nve``, or ``fix nve/sphere`` (solid spheres, I = (2/5) m r², spinning about z under
    ``enforce2d``) when the contacts have tangential forces."""
    return "nve/sphere" if model.laws.tangential else "nve"


def gravity_block(gravity_m_s2, units: UnitSystem) -> str:
    """``fix gravity`` for a uniform in-plane acceleration ``gravity_m_s2`` (gx, gy) [m/s²], if any.

    In 2D the vector must lie in the plane (a z component gives NaN coordinates).
    """
    g = np.zeros(2) if gravity_m_s2 is None else np.asarray(gravity_m_s2, float) * units.time_s**2 / units.length_m
    magnitude = float(np.hypot(*g))
    if magnitude == 0.0:
        return "# (no gravity)\n"
    return (
        f"fix             gravity all gravity {_fmt(magnitude)} vector "
        f"{_fmt(g[0] / magnitude)} {_fmt(g[1] / magnitude)} 0.0\n"
    )


def held_force_block(model: GranularModel, units: UnitSystem) -> str:
    """``fix addforce`` holding the struck bead of a precompressed packing with the force of its
    missing wall (:mod:`hexdem.model.precompression`), if any."""
    force = np.asarray(model.held_force_n) / units.force_n
    if not force.any():
        return ""
    return (
        f"group           hole id {model.packing.struck + 1}\n"
        f"fix             hole hole addforce {_fmt(force[0])} {_fmt(force[1])} 0.0\n"
    )


def impact_block(model: GranularModel, units: UnitSystem) -> str:
    """The impacts: a group of the bodies set moving with each distinct initial velocity (the
    strikers, or the struck beads themselves) and its ``velocity`` command."""
    bodies = model.impact_bodies()
    velocities = model.initial_velocities_m_s()[bodies] / units.velocity_m_s
    distinct = list(dict.fromkeys(map(tuple, velocities.tolist())))
    block = []
    for k, velocity in enumerate(distinct):
        group = "impactor" if k == 0 else f"impactor_{k + 1}"
        ids = bodies[[tuple(v) == velocity for v in velocities.tolist()]] + 1
        block += [
            f"group           {group} id {' '.join(str(i) for i in ids)}",
            f"velocity        {group} set {_fmt(velocity[0])} {_fmt(velocity[1])} 0.0 units box",
        ]
    return "\n".join(block)


def _impact_title(model: GranularModel, impact) -> str:
    """One impact in the deck's title line."""
    where = "" if impact.bead is None else " on bead {{{}, {}}}".format(*model.packing.labels[impact.bead])
    how = " by a striker" if impact.striker else ("" if where else " on the struck bead")
    return f"V0 = {impact.speed_m_s} m/s at {impact.angle_deg} deg{how}{where}"


def render_input(model: GranularModel, settings: RunSettings, gravity_m_s2=None) -> str:
    """The text of ``in.hexdem`` for ``model`` run with ``settings``, under uniform gravity
    ``gravity_m_s2`` (gx, gy) [m/s²] if given (the tilted set-up of Sec. VI-A)."""
    units = settings.units
    note = (
        "SI (m, kg, s)"
        if units.name == "si"
        else f"nondimensional A = d = M = 1 (d = {units.length_m} m, M = {units.mass_kg} kg, T = {units.time_s} s)"
    )
    walls, body_force, impacts = (
        walls_block(model, units),
        gravity_block(gravity_m_s2, units) + held_force_block(model, units),
        impact_block(model, units),
    )
    groups = 1 + sum(line.startswith("group ") for part in (walls, body_force, impacts) for line in part.splitlines())
    if groups > MAX_GROUPS:
        raise HexdemError(
            f"the deck needs {groups} LAMMPS groups (walls by material, impacts by distinct velocity), "
            f"more than LAMMPS's {MAX_GROUPS}: give the impacts fewer distinct velocities"
        )
    return template("impact.in").substitute(
        title=f"{model.packing.shape}, "
        + (
            "; ".join(_impact_title(model, impact) for impact in model.impacts)
            if len(model.impacts) <= 3
            else f"{len(model.impacts)} impacts"
        ),
        units_note=note,
        granular=granular_block(model, units),
        walls=walls,
        body_force=body_force,
        impacts=impacts,
        integrator=integrator(model),
        dt=_fmt(settings.dt_s / units.time_s),
        thermo_every=max(1, settings.n_steps // 20),
        dump_every=settings.dump_every,
        nsteps=settings.n_steps,
    )


def write_deck(model: GranularModel, settings: RunSettings, directory, gravity_m_s2=None) -> Deck:
    """Write ``data.hexdem`` and ``in.hexdem`` into ``directory`` (created if needed)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    (directory / DATA_NAME).write_text(data_file(model, settings.units))
    (directory / DECK_NAME).write_text(render_input(model, settings, gravity_m_s2))
    return Deck(directory, settings, model.n_bodies)
