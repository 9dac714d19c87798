"""Does the front of an impulse in the uncompressed lattice become round, and how fast?

The paper leaves open how the front turns from hexagonal to circular (Secs. III, VI-B). This
study strikes a half-disc of radius ``radius_beads`` d about the struck bead (the experiment's
steel beads, 0.4 m/s, 0°; only the struck edge has a wall, and the free arc of an
uncompressed packing sends nothing back) and follows the half-maximum arrival front's relative
sixfold amplitude A against its mean radius R, from a few bead diameters to beyond 150, over
one sixfold period of rays about the strike direction, each read until the front nears the
packing's edge (:func:`~hexdem.analysis.front_shape.front_times`); then it fits
:math:`A(R) = A_∞ + B (R/d)^{−p}` (:mod:`hexdem.analysis.roundness_fit`) to the signed component a6/a0
(the strike is mirror-symmetric, so b6 vanishes): positive while the front's farthest points lie
at 0° and ±60°, negative once its faces do, so that a front whose hexagon turns over is seen to.

**Control.** A hexagon of ``edge_beads`` per edge precompressed at ``control_force_n`` per
contact (a precompressed packing needs walls all round) and struck weakly by a striker
(``control_v0_m_s``, a strain far below the static one; the striker's Hertz contact, 0.38 ms,
makes a pulse of about 10 d, long against the lattice spacing, where an initial velocity
would excite every wavelength down to the spacing): its waves are linear, and the long-wave
limit of the triangular spring lattice is isotropic, so its front must become round, A → 0.
That checks the measure itself, as far as the walls let it. The control runs until its front,
at the longitudinal sound speed c_L, has crossed ``control_crossings`` times the distance to
the far wall.

``hexdem run``'s files of both runs are kept in ``OUT/uncompressed`` and ``OUT/precompressed``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from hexdem.analysis import plotting
from hexdem.analysis.front_shape import FRONT_SHAPE_COLUMNS
from hexdem.analysis.roundness_fit import fit_roundness
from hexdem.common.io import ensure_writable_dir, write_csv, write_json
from hexdem.experiments.run import measure_front_shape, run_experiment
from hexdem.model.config import RunConfig
from hexdem.model.materials import hertz_coefficient, sphere_mass
from hexdem.model.precompression import longitudinal_sound_speed, static_overlap

#: The packings of the study, in order.
PACKINGS = ("uncompressed", "precompressed")
STUDY_COLUMNS = ("packing", *FRONT_SHAPE_COLUMNS, "sixfold_cos", "sixfold_sin")
#: The first front is taken when the beads within this fraction of the smallest fitted radius
#: have been reached, so that the fronts cover the fitted range from its start.
START_RADIUS_FRACTION = 0.8


@dataclass(frozen=True)
class FrontStudy:
    """``radius_beads`` of the uncompressed half-disc (170: 52,599 beads, its window readable to
    160 d) and ``edge_beads`` of the control's hexagon (110: 35,971 beads; the window stays
    inside it to 1.5 edge lengths), MPI ``ranks`` per run and their ``launcher``, ``fronts``
    front times (evenly in log time), ``window_deg`` the rays fitted (one sixfold period about
    the strike direction, see :mod:`hexdem.analysis.front_shape`), each read until
    ``wall_margin_d`` from the packing's edge (the control's pulse is about 10 d long: closer,
    its wall's echo overlaps it), ``radius_min_d`` the smallest radius followed; the ranges of
    R fitted, ``fit_range_d`` (the uncompressed front; nearer the impact its decay is slower,
    a local exponent of 0.55 at 5-10 d against 2 beyond 30 d, which one law does not follow) and
    ``control_fit_range_d`` (the control, before its hexagon's walls tell, beyond about 60 d);
    the uncompressed impact ``v0_m_s``; the control's ``control_force_n`` per contact,
    ``control_v0_m_s`` and ``control_crossings``."""

    edge_beads: int = 110
    radius_beads: int = 170
    ranks: int = 2
    launcher: str | None = None
    fronts: int = 40
    window_deg: float = 60.0
    wall_margin_d: float = 10.0
    radius_min_d: float = 5.0
    fit_range_d: tuple[float, float] = (30.0, 160.0)
    control_fit_range_d: tuple[float, float] = (10.0, 60.0)
    v0_m_s: float = 0.4
    control_force_n: float = 20.0
    control_v0_m_s: float = 1e-4
    control_crossings: float = 1.2

    def configs(self) -> dict[str, RunConfig]:
        """The run of each packing."""
        base = RunConfig(edge_beads=self.edge_beads, ranks=self.ranks, launcher=self.launcher)
        bead, d = base.material(base.bead_material), base.diameter_m
        coefficient = float(hertz_coefficient(d, bead))
        c_l = longitudinal_sound_speed(
            self.control_force_n,
            coefficient,
            float(sphere_mass(d, bead)),
            d - static_overlap(self.control_force_n, coefficient),
        )
        far_m = math.sqrt(3) * (self.edge_beads - 1) * d
        return {
            "uncompressed": base.replace(
                shape="half-disc", edge_beads=RunConfig.edge_beads, radius_beads=self.radius_beads, v0=self.v0_m_s
            ),
            "precompressed": base.replace(
                precompression_n=self.control_force_n,
                v0=self.control_v0_m_s,
                impact="striker",
                duration=self.control_crossings * far_m / c_l,
            ),
        }


def study_front_shape(study: FrontStudy, analysis, arrival_times=None):
    """The front's shape in a run of the study (:func:`~hexdem.experiments.run.measure_front_shape`
    with the study's fronts, window and margin, from the radius ``radius_min_d`` on), by the
    half-maximum arrivals or by ``arrival_times``."""
    lattice = analysis.model.packing
    distance_d = np.hypot(*(lattice.positions_m - lattice.positions_m[lattice.struck]).T) / lattice.diameter_m
    start = float(np.mean(distance_d <= START_RADIUS_FRACTION * study.radius_min_d))  # fronts from there on
    return measure_front_shape(
        analysis,
        study.fronts,
        geometric=True,
        window_deg=study.window_deg,
        start_quantile=start,
        wall_margin_d=study.wall_margin_d,
        arrival_times=arrival_times,
    )


def run_front_study(study: FrontStudy, out, log=None) -> dict:
    """Run both packings into ``out``, fit their roundness and write ``front_shape.csv``
    (columns :data:`STUDY_COLUMNS`), ``front_shape_fit.json`` and ``front_shape.png``; returns
    the JSON's contents."""
    out = ensure_writable_dir(out)
    shapes, fits, rows = {}, {}, []
    for name, config in study.configs().items():
        analysis = run_experiment(config, out / name, log)
        shapes[name] = shape = study_front_shape(study, analysis)
        rows += [
            (name, *row, float(cos6), float(sin6))
            for row, cos6, sin6 in zip(shape.rows(), shape.sixfold_cos, shape.sixfold_sin)
        ]
    write_csv(out / "front_shape.csv", STUDY_COLUMNS, rows)  # the measurement stays if a fit fails
    for name, shape in shapes.items():
        low, high = study.fit_range_d if name == "uncompressed" else study.control_fit_range_d
        fits[name] = fit_roundness(shape.mean_radius, shape.sixfold_cos, low, high)
    labels = {
        "uncompressed": f"uncompressed half-disc, {study.v0_m_s:g} m/s",
        "precompressed": f"{study.control_force_n:g} N per contact, {study.control_v0_m_s:g} m/s (control)",
    }
    plotting.front_shape_figure(
        {labels[name]: shape for name, shape in shapes.items()},
        out / "front_shape.png",
        title="Roundness of the front as it grows",
        fits={labels[name]: fit for name, fit in fits.items()},
        signed=True,
    )
    summary = {
        "study": asdict(study),
        "fits": {name: fit.as_dict() for name, fit in fits.items()},
        "largest_radius_d": {name: float(np.nanmax(shape.mean_radius)) for name, shape in shapes.items()},
    }
    write_json(out / "front_shape_fit.json", summary)
    return summary
