"""Observation lines besides the paper's: along any lattice direction, from any bead.

A configuration's ``lines`` is a list of tables ``{name = "up", site = [m, n], angle_deg = 90}``:
the beads from site {m, n} on, one lattice step at a time along ``angle_deg`` (a multiple of
30°, :data:`~hexdem.model.triangular.DIRECTION_STEPS`), until the packing ends. The paper's ``0``,
``+30`` and ``-30`` from the struck bead are always there, first.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TypedDict

from hexdem.errors import HexdemError
from hexdem.model.packing import LabelLine, Packing
from hexdem.model.triangular import DIRECTION_STEPS


class LineTable(TypedDict, total=False):
    """A line's keys and their types (checked by :class:`~hexdem.model.config.RunConfig`)."""

    name: str
    site: tuple[int, int]
    angle_deg: float


LINE_KEYS = tuple(LineTable.__annotations__)


def with_lines(packing: Packing, entries) -> Packing:
    """``packing`` with the observation lines of ``entries`` (tables of :data:`LINE_KEYS`) after its own."""
    lines, names = [], {name for name, _, _ in packing.label_lines}
    for k, entry in enumerate(entries):
        if sorted(entry) != sorted(LINE_KEYS):
            raise HexdemError(
                f'line {k} must be a table {{name = "up", site = [m, n], angle_deg = 90}} with '
                f"exactly the keys {', '.join(LINE_KEYS)}"
            )
        name, site, angle = entry["name"], entry["site"], entry["angle_deg"]
        if not name or name in names:
            raise HexdemError(
                f"line {k}: name {name!r} must be a new, non-empty string (taken: {', '.join(sorted(names))})"
            )
        if packing.index_of(*site) is None:
            raise HexdemError(f"line {name}: site {site!r} is not a bead [m, n] of the packing")
        if angle not in DIRECTION_STEPS:
            raise HexdemError(
                f"line {name}: angle_deg {angle!r} is not a lattice direction; use one of "
                f"{', '.join(str(a) for a in DIRECTION_STEPS)}"
            )
        names.add(name)
        lines.append(LabelLine(name, (int(site[0]), int(site[1])), DIRECTION_STEPS[int(angle)]))
    return replace(packing, label_lines=packing.label_lines + tuple(lines))
