"""Weak disorder and the preparation scheme of Sec. VI-A, as LAMMPS decks.

**Diameters.** Every bead of realization k gets a diameter drawn from the normal distribution
N(d, σ), σ = 6 tol by default (tol = 0.0127 mm, the manufacturer's diameter tolerance), by
NumPy's default generator seeded with (seed, k). A realization's diameters therefore depend
on nothing else: not on the number of realizations, workers or MPI ranks (LAMMPS's own
random numbers would depend on the rank count).

**Preparation**, two damped LAMMPS runs rendered from ``lammps_inputs/settle.in``:

1. ``compact``: the lattice is spaced for its largest diameter (at least d + tol), so that
   nothing overlaps. A constant force of 5 N pushes every edge bead (a bead with fewer
   neighbours than the bulk's) inward, perpendicular to its edge (along the bisector at a
   corner). There are no walls yet, so nothing resists a rigid drift or spin of the whole
   packing: ``fix momentum`` removes both (fixed-direction forces on a rotated hexagon would
   drive the spin further). Artificial viscous drag F = −γ v settles the packing.

   Square and centered-square crystals (:mod:`hexdem.model.square_crystals`; spaced about the
   struck bead, a bead's growth taken relative to its own nominal diameter) are compacted
   inside the frame of their four walls touching the spaced crystal, pushed perpendicular to
   their own edges by :data:`CRYSTAL_PUSH_FORCE_N` = 0.05 N: a frictionless crystal with
   disordered diameters has gaps between some neighbours, and rows compressed by 5 N buckle
   sideways into them (the rows' straightness at each force: docs/guide/ensembles.md).
2. ``settle``: the walls are placed touching the compacted packing
   (:meth:`~hexdem.model.packing.Packing.with_geometry`; or ``wall_slack_m`` further out, a
   variant without prestress), the 5 N forces are removed, gravity
   g sin(tilt) acts along the strike direction (the set-up's tilt, 5° by default:
   0.855 m/s²), and a ten times weaker drag settles the packing again.

Damping times M/γ: 1.5 ms, then 15 ms. The settled packing (``settle/settled.data``, with
its contact overlaps) is the starting state of every striker velocity; the walls stay where
step 2 put them. Walls placed around the compressed packing keep part of its compression
once the 5 N are gone (overlaps of a few 0.1 µm, forces of order 1 N): even equal beads
(σ = 0) prepared this way transmit 5-17 % less than the uncompressed ideal lattice
(:mod:`hexdem.disorder.prestress` measures the load).

**Settled** means, at a check every 100 steps after at least 1000 steps: the total kinetic
energy Σ ½ m v² is below ½ (Σ m) v_rms², v_rms = 10 µm/s (4.8e-10 J for the 331 beads of
the experiment), and, for the final stage, no component of the net force on any bead
exceeds 1e-4 N (0.4 % of a bead's weight along the 5° tilt). Kinetic energy alone can be
caught near the turning point of a slow oscillation, with residual forces of a third of a
bead's weight left that would set beads moving during the impact. (The compacted packing
is held against spinning by ``fix momentum``, which leaves the pushes' small net torque as
residual forces: stage 1 uses the kinetic-energy test only.) A stage not settled after
``max_steps`` is an error. The time step is reset every 10 steps so that no bead moves more
than 0.1 µm per step, up to 20 µs: the equilibrium reached does not depend on it.

**Impact under gravity.** Gravity stays on during the impact (it holds the packing in the
state it settled in). The energy audit of such a run must include the gravitational
potential −Σ m g·u; the impact's tracker is given the gravity and adds it
(:class:`~hexdem.analysis.energy.EnergyAudit`), so that
:class:`~hexdem.analysis.impact.ImpactAnalysis` reports the drift of the conserved total.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from hexdem.common.checks import is_number
from hexdem.engines.lammps.deck import gravity_block, walls_block
from hexdem.engines.lammps.settling import SettlingStage, kinetic_tolerance_j, write_settling_deck
from hexdem.errors import HexdemError
from hexdem.model.granular import GranularModel
from hexdem.model.packing import Packing
from hexdem.model.triangular import BOND_STEPS
from hexdem.model.units import SI

#: The manufacturer's diameter tolerance of the experiment's beads, tol = 0.0127 mm.
TOLERANCE_M = 0.0127e-3
#: σ / tol of the paper's diameter distribution.
SIGMA_PER_TOLERANCE = 6.0
#: Push force [N] that compacts a square or centered-square crystal without buckling its rows
#: (see the module docstring); the hexagon takes the paper's 5 N.
CRYSTAL_PUSH_FORCE_N = 0.05
#: Standard gravity [m/s²].
STANDARD_GRAVITY_M_S2 = 9.80665
#: The two preparation stages, in order.
STAGES = ("compact", "settle")
#: Neighbour offsets {Δm, Δn} of a bead in the paper's labels: the bond steps and their opposites.
NEIGHBOURS = BOND_STEPS + tuple((-dm, -dn) for dm, dn in BOND_STEPS)
#: Off the triangular lattice, beads are neighbours when their centres are closer than this
#: times the sum of their radii.
NEIGHBOUR_REACH = 1.1
#: A bead whose neighbours' unit vectors sum to more than this is an edge bead (the bulk's sum
#: is zero to round-off; an edge bead's is at least 1).
EDGE_SUM_THRESHOLD = 1e-6


@dataclass(frozen=True)
class Disorder:
    """Per-bead diameters ~ N(``diameter_m``, ``sigma_m``) [m] (Sec. VI-A).

    ``tol_m`` is the diameter tolerance [m]; ``sigma_m`` defaults to 6 tol. σ = 0 gives the
    ideal lattice, prepared the same way.
    """

    diameter_m: float
    tol_m: float = TOLERANCE_M
    sigma_m: float | None = None

    def __post_init__(self):
        if not (is_number(self.diameter_m) and self.diameter_m > 0):
            raise HexdemError(f"bead diameter must be > 0 m, got {self.diameter_m!r}")
        if not (is_number(self.tol_m) and self.tol_m >= 0):
            raise HexdemError(f"diameter tolerance tol must be >= 0, got {self.tol_m!r} m")
        if self.sigma_m is not None and not (is_number(self.sigma_m) and self.sigma_m >= 0):
            raise HexdemError(f"diameter standard deviation sigma must be >= 0, got {self.sigma_m!r} m")

    @property
    def sigma(self) -> float:
        """σ [m]: ``sigma_m``, or 6 tol."""
        return SIGMA_PER_TOLERANCE * self.tol_m if self.sigma_m is None else float(self.sigma_m)

    def diameters_m(self, n_beads: int, seed: int, realization: int) -> np.ndarray:
        """The (n_beads,) diameters of realization ``realization`` of ensemble ``seed`` [m]."""
        rng = np.random.default_rng([int(seed), int(realization)])
        return rng.normal(self.diameter_m, self.sigma, int(n_beads))

    def spacing_m(self, diameters_m) -> float:
        """Packing spacing at which no two beads overlap: max(d + tol, largest diameter) [m]."""
        return max(self.diameter_m + self.tol_m, float(np.max(diameters_m)))


@dataclass(frozen=True)
class Preparation:
    """The damped settling of Sec. VI-A (see the module docstring), in SI units.

    ``push_force_n`` inward force on edge beads in stage 1 [N]; ``tilt_deg`` tilt of the set-up,
    gravity g sin(tilt) along the strike [deg]; ``gravity_m_s2`` g; ``compact_damping_s`` and
    ``settle_damping_s`` damping times M/γ of the two stages [s]; ``wall_slack_m`` how far
    the walls of stage 2 stand back from touching the compacted packing [m] (0: the paper's
    scheme, which keeps a prestress; a slack larger than the compaction's overlaps gives a
    packing held by gravity alone); ``settled_rms_speed_m_s`` and
    ``settled_max_force_n`` the rms bead speed [m/s] and the net force component [N] below which
    a stage is settled; ``max_dt_s`` and ``max_step_m`` bound the
    time step and the distance a bead moves per step; ``check_every``, ``min_steps`` and
    ``max_steps`` schedule the kinetic-energy check.
    """

    push_force_n: float = 5.0
    tilt_deg: float = 5.0
    gravity_m_s2: float = STANDARD_GRAVITY_M_S2
    compact_damping_s: float = 1.5e-3
    settle_damping_s: float = 15e-3
    wall_slack_m: float = 0.0
    settled_rms_speed_m_s: float = 1e-5
    settled_max_force_n: float = 1e-4
    max_dt_s: float = 2e-5
    max_step_m: float = 1e-7
    check_every: int = 100
    min_steps: int = 1000
    max_steps: int = 1_000_000

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            may_be_zero = f.name in ("tilt_deg", "wall_slack_m")
            if not is_number(value) or value < 0 or (value == 0 and not may_be_zero):
                raise HexdemError(
                    f"preparation parameter {f.name} must be a {'non-negative' if may_be_zero else 'positive'} "
                    f"number, got {value!r}"
                )
            if f.type == "int" and int(value) != value:
                raise HexdemError(f"preparation parameter {f.name} must be an integer, got {value!r}")
        if self.tilt_deg >= 90:
            raise HexdemError(f"tilt must be below 90 degrees, got {self.tilt_deg!r}")

    def gravity_vector_m_s2(self, direction) -> np.ndarray:
        """In-plane gravity of the tilted set-up: g sin(tilt) along the strike ``direction``."""
        return self.gravity_m_s2 * math.sin(math.radians(self.tilt_deg)) * np.asarray(direction, float)

    def kinetic_tolerance_j(self, masses_kg) -> float:
        """The settling criterion: Σ ½ m v² below ½ (Σ m) v_rms² [J]
        (:func:`~hexdem.engines.lammps.settling.kinetic_tolerance_j`)."""
        return kinetic_tolerance_j(masses_kg, self.settled_rms_speed_m_s)


def walls_for_settling(compacted: Packing, preparation: Preparation) -> Packing:
    """The compacted packing with the walls of stage 2: touching it, moved back by the slack."""
    walls = tuple(replace(wall, offset_m=wall.offset_m - preparation.wall_slack_m) for wall in compacted.walls)
    return replace(compacted, walls=walls)


def edge_directions(lattice: Packing) -> np.ndarray:
    """(N, 2) inward unit vectors of the edge beads (zero for interior beads).

    An edge bead misses some of the neighbours a bead of the bulk has; it is pushed away from
    the missing ones, along the sum of the unit vectors to the neighbours it has: perpendicular
    to a straight edge, along the bisector at a corner. The triangular lattice reads its six
    neighbours from the labels; any other packing (square, centered-square) from the geometry
    (:func:`geometric_neighbour_sums`).
    """
    if lattice.bond_steps:
        unit = {step: np.array([np.sqrt(3) / 2 * step[1], step[0] / 2]) for step in NEIGHBOURS}
        directions = np.zeros((len(lattice), 2))
        for i, (m, n) in enumerate(lattice.labels.tolist()):
            for dm, dn in NEIGHBOURS:
                if lattice.index_of(m + dm, n + dn) is None:
                    directions[i] -= unit[(dm, dn)]
    else:
        directions = geometric_neighbour_sums(lattice.positions_m, lattice.diameters_m)
    norms = np.linalg.norm(directions, axis=1)
    edge = norms > EDGE_SUM_THRESHOLD
    directions[edge] /= norms[edge, None]
    directions[~edge] = 0.0
    return directions


def geometric_neighbour_sums(positions_m, diameters_m) -> np.ndarray:
    """(N, 2) sum over each bead's neighbours of the unit vectors towards them: zero in the bulk of
    a crystal, pointing inward at its edges. Neighbours: centres closer than
    :data:`NEIGHBOUR_REACH` times the sum of the radii (a lattice spaced for its largest diameter
    keeps its neighbours; a square's diagonal, √2 d away, is none)."""
    from scipy.spatial import cKDTree

    positions, diameters = np.asarray(positions_m, float), np.asarray(diameters_m, float)
    pairs = cKDTree(positions).query_pairs(NEIGHBOUR_REACH * float(diameters.max()), output_type="ndarray")
    i, j = pairs.T if len(pairs) else (np.zeros(0, int), np.zeros(0, int))
    offsets = positions[j] - positions[i]
    distances = np.linalg.norm(offsets, axis=1)
    near = distances < NEIGHBOUR_REACH * (diameters[i] + diameters[j]) / 2
    units = offsets[near] / distances[near, None]
    sums = np.zeros_like(positions)
    np.add.at(sums, i[near], units)
    np.add.at(sums, j[near], -units)
    return sums


def spaced_packing(lattice: Packing, diameters_m, disorder: Disorder) -> Packing:
    """``lattice`` with the given diameters, its positions scaled about the struck bead so that
    nothing overlaps: by :meth:`Disorder.spacing_m` over d, or more where a bead grew by a larger
    share of its own nominal diameter (a centered-square's small interstitials)."""
    diameters_m = np.asarray(diameters_m, float)
    scale = max(disorder.spacing_m(diameters_m) / lattice.diameter_m, float(np.max(diameters_m / lattice.diameters_m)))
    origin = lattice.positions_m[lattice.struck]
    return lattice.with_geometry(origin + (lattice.positions_m - origin) * scale, diameters_m)


def _push_block(model: GranularModel, preparation: Preparation, framed: bool) -> str:
    """Constant inward forces on the edge beads, grouped by direction, and (when no frame holds
    the packing, ``framed`` False) fix momentum."""
    directions = edge_directions(model.packing)
    groups: dict[tuple[float, float], list[int]] = {}
    for i in np.flatnonzero(np.any(directions != 0, axis=1)):
        groups.setdefault(tuple(np.round(directions[i], 9)), []).append(int(i))
    lines = []
    for k, members in enumerate(groups[key] for key in sorted(groups)):
        force = preparation.push_force_n * directions[members[0]]
        ids = [i + 1 for i in members]
        lines += [
            f"group           push_{k} id {' '.join(map(str, ids))}",
            f"fix             push_{k} push_{k} addforce {float(force[0])!r} {float(force[1])!r} 0.0",
        ]
    if not framed:
        lines.append("fix             rigid_modes all momentum 10 linear 1 1 0 angular")
    return "\n".join(lines) + "\n"


def _stage_blocks(model: GranularModel, stage: str, preparation: Preparation) -> dict:
    """What differs between the stages: walls, loads, damping time, force criterion (None: none)."""
    if stage == "compact":
        framed = not model.packing.bond_steps
        return {
            "walls": walls_block(model, SI)
            if framed
            else "# (none yet: they are placed touching the compacted packing)\n",
            "loads": _push_block(model, preparation, framed),
            "damping_s": preparation.compact_damping_s,
            "loads_note": f"{preparation.push_force_n:g} N inward on every edge bead; "
            + ("the frame of walls touching the spaced crystal holds it" if framed else "rigid drift and spin removed"),
            "force_tolerance": None,
        }
    return {
        "walls": walls_block(model, SI),
        "loads": gravity_block(preparation.gravity_vector_m_s2(model.impact.direction), SI),
        "damping_s": preparation.settle_damping_s,
        "loads_note": f"gravity of the {preparation.tilt_deg:g} deg tilt along the strike, no push",
        "force_tolerance": preparation.settled_max_force_n,
    }


def write_stage_deck(model: GranularModel, stage: str, preparation: Preparation, directory) -> Path:
    """Render the deck of preparation ``stage`` ("compact" or "settle") for ``model``'s lattice
    (:func:`~hexdem.engines.lammps.settling.write_settling_deck`).

    ``model`` supplies the packing (positions, diameters, walls) and the materials; its
    impact is not part of the deck. Returns the deck directory.
    """
    if stage not in STAGES:
        raise HexdemError(f"unknown preparation stage {stage!r}; known: {', '.join(STAGES)}")
    blocks = _stage_blocks(model, stage, preparation)
    return write_settling_deck(
        model,
        SettlingStage(
            name=stage,
            purpose="Preparation of a weakly disordered packing (Sec. VI-A).",
            walls=blocks["walls"],
            loads=blocks["loads"],
            loads_note=blocks["loads_note"],
            damping_s=blocks["damping_s"],
            force_tolerance_n=blocks["force_tolerance"],
            settled_rms_speed_m_s=preparation.settled_rms_speed_m_s,
            max_step_m=preparation.max_step_m,
            max_dt_s=preparation.max_dt_s,
            check_every=preparation.check_every,
            min_steps=preparation.min_steps,
            max_steps=preparation.max_steps,
        ),
        directory,
    )
