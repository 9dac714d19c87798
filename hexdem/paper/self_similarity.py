"""The paper's first open question: does the decaying pulse become self-similar?

The Conclusions leave open whether "self-similar decaying solutions" exist in the hexagonal
lattice. This study answers it for the leading pulse.

**Set-up** (:class:`SelfSimilarityStudy`): the front study's two packings
(:class:`~hexdem.experiments.front_study.FrontStudy`), struck as there: the uncompressed
half-disc of radius 170 d (52,599 beads, 0.4 m/s) and, as a control whose waves are linear, the
110-per-edge hexagon precompressed at 20 N and struck weakly. The speeds of the beads nearest
the rays at 0°, 15° and 30° from the struck bead, one every diameter from 5 d to
``radius_max_d``, are recorded at every sample of the run (no dump).

**Per ray** (:func:`measure_ray`, :mod:`hexdem.analysis.pulse_shape`): each bead's leading
pulse, its amplitude v_m, width w (full width at half maximum) and arrival t_a; the local front
speed :math:`c = dr/dt_a` (centred differences over :data:`SPEED_STEP` beads on each side); power
laws :math:`v_m ∝ r^a`, :math:`w ∝ r^b`, :math:`c ∝ r^s` fitted over ``fit_range_d`` with their
standard errors; and each profile :math:`v/v_m` against :math:`(t − t_a)/w`, with its RMS distance
from the mean profile of the beads in the outer third of the fit range.

**Verdict.** The pulse is called self-similar along a ray when the profiles of the middle third
of the fit range lie within :data:`COLLAPSE_TOLERANCE` (RMS, in units of the peak) of that outer
shape: then amplitude, width and speed are the whole story, with the exponents above.

**Energy budget.** The energy the leading pulse carries across a ring of radius r scales as
:math:`r v_m^2 w c`, that is as :math:`r^e` with :math:`e = 1 + 2a + b + s`. e = 0 (within two standard
errors): the pulse keeps its energy; e < 0: it leaks into the tail behind it, as :math:`r^e`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from hexdem.analysis.pulse_shape import collapse_residuals, power_law, profiles, pulse_shapes, reference_profile
from hexdem.experiments.front_study import FrontStudy
from hexdem.model.model_builder import build_packing
from hexdem.model.packing import Packing

#: The rays followed, degrees from the strike direction (the two lattice lines and between).
RAYS_DEG = (0.0, 15.0, 30.0)
#: Beads on each side of the centred difference that gives the local front speed.
SPEED_STEP = 3
#: The largest RMS distance of a self-similar pulse's profiles from the outer shape.
COLLAPSE_TOLERANCE = 0.05
#: The studies, in order.
STUDIES = ("uncompressed", "precompressed")


@dataclass(frozen=True)
class SelfSimilarityStudy:
    """``front``: the packings and impacts (:class:`FrontStudy`); per study, the largest
    distance recorded and the range fitted [d] (the control's is kept inside its hexagon, where
    the walls' echoes stay behind the leading pulse)."""

    front: FrontStudy = field(default_factory=FrontStudy)
    radius_min_d: float = 5.0
    radius_max_d: dict = field(default_factory=lambda: {"uncompressed": 160.0, "precompressed": 90.0})
    fit_range_d: dict = field(default_factory=lambda: {"uncompressed": (10.0, 160.0), "precompressed": (10.0, 90.0)})

    @classmethod
    def quick(cls) -> SelfSimilarityStudy:
        """The test suite's version: a half-disc of 40 d and a hexagon of 30 per edge."""
        return cls(
            FrontStudy(edge_beads=30, radius_beads=40, fit_range_d=(8.0, 35.0)),
            radius_max_d={"uncompressed": 35.0, "precompressed": 24.0},
            fit_range_d={"uncompressed": (8.0, 35.0), "precompressed": (8.0, 24.0)},
        )

    def as_dict(self) -> dict:
        return asdict(self)


def ray_beads(lattice: Packing, angle_deg: float, radius_min_d: float, radius_max_d: float) -> np.ndarray:
    """Indices of the beads nearest the points of the ray at ``angle_deg`` from the struck bead,
    one every diameter from ``radius_min_d`` to ``radius_max_d`` (each bead once, in order of
    distance)."""
    d = lattice.diameter_m
    origin = lattice.positions_m[lattice.struck]
    direction = np.array([np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))])
    radii = np.arange(radius_min_d, radius_max_d + 0.5) * d
    points = origin + radii[:, None] * direction
    nearest = [int(np.argmin(np.hypot(*(lattice.positions_m - point).T))) for point in points]
    return np.array(list(dict.fromkeys(nearest)))


@dataclass(frozen=True)
class Ray:
    """One ray's beads: ``distance_d`` (B,), the leading pulses' ``peak_speed`` [m/s],
    ``width_s``, ``arrival_time_s``, ``front_speed_m_s`` (NaN at the ends), ``profile_residual``;
    the fitted ``exponents`` {name: (value, stderr)} over ``fit_range_d`` and the collapse
    ``middle_residual`` (median over the middle third of the range)."""

    distance_d: np.ndarray
    peak_speed: np.ndarray
    width_s: np.ndarray
    arrival_time_s: np.ndarray
    front_speed_m_s: np.ndarray
    profile_residual: np.ndarray
    profiles: np.ndarray
    exponents: dict
    middle_residual: float
    fit_range_d: tuple[float, float]

    @property
    def self_similar(self) -> bool:
        return bool(self.middle_residual < COLLAPSE_TOLERANCE)

    def energy_exponent(self) -> tuple[float, float]:
        """(e, its standard error) of the energy crossing a ring, :math:`r v_m^2 w c ∝ r^e`; the error
        treats the three fitted exponents as independent, though they come from the same beads."""
        (a, sa), (b, sb), (s, ss) = (self.exponents[k] for k in ("amplitude", "width", "speed"))
        return 1 + 2 * a + b + s, float(np.sqrt(4 * sa**2 + sb**2 + ss**2))


def local_front_speed(distance_m: np.ndarray, arrival_s: np.ndarray, step: int = SPEED_STEP) -> np.ndarray:
    """dr/dt_a by centred differences over ``step`` beads on each side (NaN within ``step`` of
    either end)."""
    speed = np.full(len(distance_m), np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        speed[step:-step] = (distance_m[2 * step :] - distance_m[: -2 * step]) / (
            arrival_s[2 * step :] - arrival_s[: -2 * step]
        )
    return speed


def measure_ray(times_s, speeds, distance_d, diameter_m: float, fit_range_d: tuple[float, float]) -> Ray:
    """The pulse along one ray from its beads' speed signals ``speeds`` (S, B) at ``times_s``."""
    shapes = pulse_shapes(times_s, speeds)
    front = local_front_speed(distance_d * diameter_m, shapes.arrival)
    low, high = fit_range_d
    fitted = (distance_d >= low) & (distance_d <= high)
    exponents = {
        name: power_law(distance_d[fitted], values[fitted])
        for name, values in (("amplitude", shapes.peak), ("width", shapes.width), ("speed", front))
    }
    shape_rows = profiles(times_s, speeds, shapes)
    third = (high - low) / 3
    outer = fitted & (distance_d >= high - third)
    middle = fitted & (distance_d >= low + third) & (distance_d < high - third)
    residual = collapse_residuals(shape_rows, reference_profile(shape_rows[outer]))
    return Ray(
        distance_d,
        shapes.peak,
        shapes.width,
        shapes.arrival,
        front,
        residual,
        shape_rows,
        exponents,
        float(np.nanmedian(residual[middle])),
        fit_range_d,
    )


def run_study_packing(study: SelfSimilarityStudy, name: str, workdir, log=None) -> dict[str, Ray]:
    """Run one packing (``name`` of :data:`STUDIES`) with its rays traced; {ray: Ray}."""
    from hexdem.experiments.run import simulate

    config = study.front.configs()[name]
    lattice = build_packing(config)
    rays = {f"{angle:g}": ray_beads(lattice, angle, study.radius_min_d, study.radius_max_d[name]) for angle in RAYS_DEG}
    traced = [int(b) for beads in rays.values() for b in beads]
    analysis = simulate(config, workdir, log, trace_beads=traced)
    column = {int(bead): k for k, bead in enumerate(analysis.tracked.trace_beads)}
    times_s = analysis.tracked.trace_times * analysis.settings.units.time_s
    origin = lattice.positions_m[lattice.struck]
    measured = {}
    for ray, beads in rays.items():
        speeds = (
            analysis.tracked.trace_speeds[:, [column[int(b)] for b in beads]] * analysis.settings.units.velocity_m_s
        )
        distance_d = np.hypot(*(lattice.positions_m[beads] - origin).T) / lattice.diameter_m
        measured[ray] = measure_ray(times_s, speeds, distance_d, lattice.diameter_m, study.fit_range_d[name])
    return measured
