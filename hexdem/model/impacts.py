"""The impacts of a configuration as data: any number, each on any bead, or a flat striker on an edge.

A configuration's ``impacts`` is a list of tables; left empty, the paper's single impact on the
struck bead {0, 0} is the run's (``v0``, ``strike_angle_deg``, ``impact``). Each table strikes
either

* ``site = [m, n]``: one bead, boundary or interior (the first impact's bead is *the* struck
  bead: the origin of the observation lines and of the regions' bounds), or
* ``edge_deg = A``: every bead of the packing's edge whose inward normal points at A degrees
  from +x (0: the struck edge, 180: the far edge of a hexagon), all at once and along that
  normal: a flat striker, the plane-wave-like excitation of Hua & Van Gorder. As velocities,
  the edge moves off as one; as strikers, a row of touching spheres, one per bead, hits it (a
  plate that the beads may break up).

and may set ``v0`` (in the run's units), ``angle_deg`` (the direction of motion from +x; for
an edge, its inward normal), ``kind`` ("velocity" or "striker"), ``striker_material`` and
``striker_diameter_m``; each defaults to the run's own. Every struck bead sits in a hole of each
wall it would be pushed through, whatever the impacts' order (:func:`cut_holes`); a bead
nothing strikes sits in none, {0, 0} included. An edge must be flat (two beads at least).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypedDict

from hexdem.errors import HexdemError
from hexdem.model.granular import Impact
from hexdem.model.packing import Packing, unit_vector
from hexdem.model.walls import facing_edge


class ImpactTable(TypedDict, total=False):
    """An impact's keys and their types (checked by :class:`~hexdem.model.config.RunConfig`)."""

    site: tuple[int, int]
    edge_deg: float
    v0: float
    angle_deg: float
    kind: str
    striker_material: str
    striker_diameter_m: float


#: The keys of one impact's table.
IMPACT_KEYS = tuple(ImpactTable.__annotations__)
KINDS = ("velocity", "striker")


@dataclass(frozen=True)
class ImpactSpec:
    """One impact as configured: ``site`` (m, n) or ``edge_deg``; ``v0`` in the run's units;
    ``angle_deg`` (None: along the edge's normal); ``kind``; the striker's material name and
    diameter [m] (None: the beads')."""

    site: tuple[int, int] | None
    edge_deg: float | None
    v0: float
    angle_deg: float | None
    kind: str
    striker_material: str | None
    striker_diameter_m: float | None

    @property
    def striker(self) -> bool:
        return self.kind == "striker"


def impact_specs(entries, v0, angle_deg, kind, striker_material, striker_diameter_m) -> list[ImpactSpec]:
    """The :class:`ImpactSpec` of each table of ``entries``, the run's values as defaults; none
    given, the run's single impact on {0, 0}."""
    if not entries:
        return [ImpactSpec((0, 0), None, v0, angle_deg, kind, striker_material, striker_diameter_m)]
    specs = []
    for k, entry in enumerate(entries):
        unknown = sorted(set(entry) - set(IMPACT_KEYS))
        if unknown:
            raise HexdemError(f"impact {k}: unknown key(s) {', '.join(unknown)}; known: {', '.join(IMPACT_KEYS)}")
        if ("site" in entry) == ("edge_deg" in entry):
            raise HexdemError(f"impact {k}: give exactly one of site = [m, n] (one bead) and edge_deg (a whole edge)")
        site = entry.get("site")
        site = None if site is None else (int(site[0]), int(site[1]))
        if "v0" in entry and not entry["v0"] > 0:
            raise HexdemError(f"impact {k}: v0 must be > 0, got {entry['v0']!r}")
        chosen_kind = entry.get("kind", kind)
        if chosen_kind not in KINDS:
            raise HexdemError(f"impact {k}: unknown kind {chosen_kind!r}; use one of: {', '.join(KINDS)}")
        default_angle = angle_deg if site is not None else None
        specs.append(
            ImpactSpec(
                site,
                entry.get("edge_deg"),
                entry.get("v0", v0),
                entry.get("angle_deg", default_angle),
                chosen_kind,
                entry.get("striker_material", striker_material),
                entry.get("striker_diameter_m", striker_diameter_m),
            )
        )
    return specs


def struck_site(specs: list[ImpactSpec]) -> tuple[int, int]:
    """The struck bead's site: the first impact's, or {0, 0} when it strikes an edge."""
    return specs[0].site if specs[0].site is not None else (0, 0)


def resolve_impacts(specs: list[ImpactSpec], packing: Packing, velocity_scale_m_s: float, material) -> list[Impact]:
    """The model's :class:`Impact` s of ``specs`` on ``packing`` (an edge: one per bead of it);
    ``velocity_scale_m_s`` converts the run's speeds to m/s and ``material(name)`` finds a
    material."""
    impacts = []
    for k, spec in enumerate(specs):
        if spec.site is not None:
            bead = packing.index_of(*spec.site)
            if bead is None:
                raise HexdemError(f"impact {k}: site {{{spec.site[0]}, {spec.site[1]}}} is not a bead of the packing")
            beads, angle = [bead], spec.angle_deg
        else:
            beads = facing_edge(packing, unit_vector(spec.edge_deg))[1]  # the beads a wall there would touch
            if len(beads) < 2:
                raise HexdemError(
                    f"impact {k}: the packing has no flat edge whose inward normal points at "
                    f"{spec.edge_deg:g}° (one bead there); use the angle of a wall, e.g. 0"
                )
            angle = spec.edge_deg if spec.angle_deg is None else spec.angle_deg
        striker = material(spec.striker_material) if spec.striker_material is not None else None
        impacts += [
            Impact(
                spec.v0 * velocity_scale_m_s, float(angle), spec.striker, int(bead), striker, spec.striker_diameter_m
            )
            for bead in beads
        ]
    return impacts
