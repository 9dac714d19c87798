"""The beads a sensor particle may replace, named as a configuration's ``sensors`` name them
(:mod:`hexdem.model.sensors`): ``"line:n"`` for a bead of an observation line, else its bead id.

The struck bead is never a candidate: the striker hits it. The paper's three configurations
(Sec. II; the text's positions on the 11-per-edge lattice, Fig. 1's exact beads not being in the
text) are :data:`PAPER_CONFIGURATIONS`.
"""

from __future__ import annotations

from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.sensors import sensor_beads

#: The paper's configurations of four sensors: along 0°; across the 0° line near the impact; across
#: it four layers further, and the sensor nearest the impact in all three.
PAPER_CONFIGURATIONS = {
    "1": ("0:1", "0:3", "0:5", "0:7"),
    "2": ("0:1", "+30:2", "-30:2", "+30:3"),
    "3": ("0:1", "0:4", "+30:8", "-30:8"),
}
#: ``--candidates`` words: every bead, or the beads of the observation lines.
CANDIDATE_SETS = ("all", "lines")


def is_paper_lattice(config: RunConfig) -> bool:
    """Whether ``config`` strikes the paper's 11-per-edge hexagon, on which its configurations lie."""
    return config.shape == "hexagon" and config.edge_beads == 11


def sensor_value(label: str) -> str | int:
    """A label as a configuration's ``sensors`` takes it: a bead id as an integer."""
    return int(label) if label.isdigit() else label


def candidate_labels(config: RunConfig, spec: str) -> list[str]:
    """The candidates of ``--candidates spec`` on ``config``'s packing, in bead order: ``all``,
    ``lines`` or a comma-separated list of sensors; a list naming no bead, or the struck one, is
    one line."""
    model = build_model(config.replace(sensors=()))
    packing, struck = model.packing, set(int(b) for b in model.struck_beads)
    named = {}
    for line, beads in packing.lines().items():
        for n, bead in enumerate(beads):
            named.setdefault(int(bead), f"{line}:{n}")
    if spec in CANDIDATE_SETS:
        beads = range(len(packing)) if spec == "all" else sorted(named)
        return [named.get(b, str(b + 1)) for b in beads if b not in struck]
    labels = [word.strip() for word in spec.split(",") if word.strip()]
    if not labels:
        raise HexdemError(f"--candidates {spec!r}: all, lines, or a list of sensors such as 0:1,0:3,+30:2")
    try:
        beads = sensor_beads([sensor_value(label) for label in labels], packing)
    except HexdemError as exc:
        raise HexdemError(f"--candidates: {exc}") from None
    hit = [label for label, bead in beads.items() if bead in struck]
    if hit:
        raise HexdemError(f"--candidates: {hit[0]} is the struck bead; a sensor there would be struck")
    return labels
