"""Sensor particles: the beads a configuration's ``sensors`` name.

A sensor is ``"line:n"``, bead n of an observation line (one of the paper's ``0``, ``+30``,
``-30`` or of the configuration's extra ``lines``; n = 0 is the line's first bead), or a bead id
(from 1). Each names one bead of the packing, and no two the same.
"""

from __future__ import annotations

from hexdem.errors import HexdemError
from hexdem.model.packing import Packing


def sensor_beads(sensors, packing: Packing) -> dict[str, int]:
    """{label: bead index} of ``sensors`` on ``packing``, in the order given."""
    beads, lines = {}, packing.lines() if sensors else {}
    for sensor in sensors:
        if isinstance(sensor, int) and not isinstance(sensor, bool):
            if not 1 <= sensor <= len(packing):
                raise HexdemError(f"sensor bead id {sensor} is not in the packing (ids 1 to {len(packing)})")
            beads[str(sensor)] = sensor - 1
            continue
        name, _, n = str(sensor).partition(":")
        if name not in lines or not n.isdigit():
            raise HexdemError(
                f"sensor {sensor!r} is neither a bead id nor 'line:n' with line one of {', '.join(lines)}"
            )
        line = lines[name]
        if int(n) >= len(line):
            raise HexdemError(f"sensor {sensor!r}: line {name} has beads 0 to {len(line) - 1}")
        beads[str(sensor)] = int(line[int(n)])
    if len(set(beads.values())) != len(sensors):
        raise HexdemError(f"sensors {list(sensors)} name the same bead twice")
    return beads
