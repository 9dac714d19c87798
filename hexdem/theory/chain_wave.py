"""The chain's solitary wave beside the hexagon's decay: the contrast the paper's Sec. I draws.

A chain of :data:`CHAIN_BEADS` steel spheres, listed as the sites {k, k} of a contact row (the
+30° line, spacing d) with no walls, is struck on bead 0 along the row, as the experiment's
hexagon is struck on its edge's centre (a velocity impact of V0 on one bead, both). The chain's
pulse forms within a few beads and then travels unchanged: :func:`measure_chain` reads it over
the beads of :data:`WINDOW`, where it has formed and the free end is still far.

* ``front_speed_m_s``: least squares of the beads' distances n d against their arrival times
  (half maximum, :mod:`hexdem.analysis.peaks`);
* ``peak_velocity_m_s``: their mean peak speed V_m, and ``peak_ratio`` the last bead's over the
  first's (1 for a pulse that keeps its amplitude);
* ``nesterenko_speed_m_s``: the continuum law at that V_m (:func:`~hexdem.model.solitary_wave.solitary_speed_m_s`),
  ``relative_deviation`` the measured speed's from it;
* ``half_maximum_width_d``: the time the middle bead's speed stays above half its peak
  (:func:`~hexdem.analysis.pulse_shape.pulse_shapes`), times
  the front speed, in diameters, beside the continuum's (:data:`~hexdem.model.solitary_wave.HALF_MAXIMUM_WIDTH_D`,
  of a pulse spanning :data:`~hexdem.model.solitary_wave.SUPPORT_WIDTH_D` ≈ 5 d).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from hexdem.analysis.pulse_shape import pulse_shapes
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.solitary_wave import (
    HALF_MAXIMUM_WIDTH_D,
    SUPPORT_WIDTH_D,
    chain_speed_scale_m_s,
    solitary_speed_m_s,
)

#: Beads of the chain.
CHAIN_BEADS = 80
#: First and last bead n of the chain read (the pulse has formed by n = 20: its peak is then
#: constant to 1e-6; the free end, which the last bead flies off, is 20 beads further).
WINDOW = (20, 60)
#: The chain's row: the +30° line of the sites {k, k}.
CHAIN_LINE = "+30"


def chain_config(v0_m_s: float = 0.4, n_beads: int = CHAIN_BEADS) -> RunConfig:
    """The chain struck at ``v0_m_s``, run until a pulse as slow as that of V_m = V0/2 (slower
    than any the impact makes) has crossed it."""
    config = RunConfig(
        shape="sites", sites=[[k, k] for k in range(n_beads)], site_walls_deg=[], strike_angle_deg=30.0, v0=v0_m_s
    )
    slowest = solitary_speed_m_s(chain_speed_scale_m_s(build_model(config).bead), v0_m_s / 2)
    return config.replace(duration=n_beads * config.diameter_m / slowest)


@dataclass(frozen=True)
class ChainWave:
    """What the chain's pulse does over :data:`WINDOW` (see the module docstring); SI units."""

    front_speed_m_s: float
    nesterenko_speed_m_s: float
    relative_deviation: float
    peak_velocity_m_s: float
    peak_ratio: float
    half_maximum_width_d: float
    continuum_half_maximum_width_d: float = HALF_MAXIMUM_WIDTH_D
    continuum_support_width_d: float = SUPPORT_WIDTH_D
    window: tuple[int, int] = WINDOW

    def as_dict(self) -> dict:
        return asdict(self)


def measure_chain(analysis, window: tuple[int, int] = WINDOW) -> ChainWave:
    """The chain's pulse (see the module docstring) from a run of :func:`chain_config` that
    traced :data:`CHAIN_LINE`, in SI units."""
    if analysis.settings.units.name != "si":
        raise HexdemError('the chain\'s pulse is measured in SI units; run the chain with units = "si"')
    r = analysis.results
    beads = r.lines[CHAIN_LINE]
    first, last = window
    if last >= len(beads):
        raise HexdemError(f"the window {first}..{last} goes beyond the chain's {len(beads)} beads")
    n = np.arange(first, last + 1)
    diameter = analysis.model.packing.diameter_m
    arrival, peak = r.arrival_time[beads[n]], r.peak_speed[beads[n]]
    if not np.all(np.isfinite(arrival)):
        raise HexdemError("the pulse did not reach every bead of the window: the run was too short")
    speed = float(np.polyfit(arrival, n * diameter, 1)[0])
    peak_velocity = float(np.mean(peak))
    law = solitary_speed_m_s(chain_speed_scale_m_s(analysis.model.bead), peak_velocity)
    times, speeds = analysis.line_trace(CHAIN_LINE)
    duration = pulse_shapes(times, speeds[:, [(first + last) // 2]]).width[0]
    if not np.isfinite(duration):
        raise HexdemError("the pulse is cut by the run's start or end: no width at half maximum")
    width = float(duration) * speed / diameter
    return ChainWave(speed, law, speed / law - 1, peak_velocity, float(peak[-1] / peak[0]), width)
