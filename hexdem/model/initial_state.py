"""Any initial state: per-bead velocities, and displacements from the packed positions.

``initial_state_file`` is a CSV whose header is ``m,n,vx,vy`` or ``m,n,vx,vy,dx,dy``: one bead
per line, by its label {m, n}, its initial velocity [m/s] and optionally its displacement [m]
from where the packing (precompressed or not) puts it. Beads not listed start at rest where the
packing puts them. The impacts add their speeds on top
(:meth:`~hexdem.model.granular.GranularModel.initial_velocities_m_s`).
Both engines start from :meth:`~hexdem.model.granular.GranularModel.initial_positions_m` and
that method, so they read the state alike.

A displacement of half a diameter or more is refused (it would put the bead inside its
neighbours; beads displaced towards each other may still overlap, which is the state asked
for), as are unknown or repeated sites and values that are not finite numbers.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexdem.common.io import read_text, write_csv
from hexdem.errors import HexdemError
from hexdem.model.packing import Packing

#: The accepted headers.
HEADERS = (("m", "n", "vx", "vy"), ("m", "n", "vx", "vy", "dx", "dy"))


@dataclass(frozen=True, eq=False)
class InitialState:
    """(N, 2) ``velocities_m_s`` and ``displacements_m`` of the packing's N beads."""

    velocities_m_s: np.ndarray
    displacements_m: np.ndarray


def read_initial_state(path, packing: Packing) -> InitialState:
    """The state in the CSV at ``path`` for the beads of ``packing`` (see the module docstring)."""
    path = Path(path)
    name = f"initial_state_file {path}"
    lines = [line for line in read_text(path, "initial_state_file").splitlines() if line.strip()]
    rows = list(csv.reader(lines))
    header = tuple(cell.strip() for cell in rows[0]) if rows else ()
    if header not in HEADERS:
        raise HexdemError(
            f"{name}: the header must be m,n,vx,vy or m,n,vx,vy,dx,dy, got {','.join(header) or 'nothing'}"
        )
    n = len(packing)
    velocities, displacements, seen = np.zeros((n, 2)), np.zeros((n, 2)), set()
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise HexdemError(f"{name}, line {number}: {len(row)} values, the header has {len(header)}")
        try:
            m, k = int(row[0]), int(row[1])
            values = [float(cell) for cell in row[2:]]
        except ValueError:
            raise HexdemError(f"{name}, line {number}: m and n must be integers and the rest numbers") from None
        if not all(math.isfinite(v) for v in values):
            raise HexdemError(f"{name}, line {number}: the values must be finite numbers")
        bead = packing.index_of(m, k)
        if bead is None:
            raise HexdemError(f"{name}, line {number}: site {{{m}, {k}}} is not a bead of the packing")
        if bead in seen:
            raise HexdemError(f"{name}, line {number}: site {{{m}, {k}}} is listed twice")
        seen.add(bead)
        velocities[bead] = values[:2]
        if len(values) == 4:
            if math.hypot(*values[2:]) >= packing.diameters_m[bead] / 2:
                raise HexdemError(
                    f"{name}, line {number}: a displacement of half a diameter or more would put "
                    f"bead {{{m}, {k}}} inside its neighbours"
                )
            displacements[bead] = values[2:]
    return InitialState(velocities, displacements)


def write_initial_state(path, packing: Packing, velocities_m_s, displacements_m=None) -> None:
    """Write (N, 2) ``velocities_m_s`` and optionally ``displacements_m`` of ``packing``'s beads
    as an ``initial_state_file`` (atomically), every bead on its own line, full precision."""
    columns = [np.asarray(velocities_m_s, float)]
    if displacements_m is not None:
        columns.append(np.asarray(displacements_m, float))
    if any(column.shape != (len(packing), 2) for column in columns):
        raise HexdemError(
            f"an initial state needs ({len(packing)}, 2) arrays for the packing's beads, got "
            f"{' and '.join(str(column.shape) for column in columns)}"
        )
    header = HEADERS[len(columns) - 1]
    rows = [
        [m, n, *(repr(float(value)) for value in values)]
        for (m, n), values in zip(packing.labels.tolist(), np.hstack(columns))
    ]
    write_csv(path, header, rows)
