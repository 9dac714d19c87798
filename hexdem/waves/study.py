"""The precompressed lattice's linear waves in one study: its Dirac point, measured.

:func:`run_dirac_study` measures the dispersion (:mod:`hexdem.waves.dispersion`), conical
diffraction and its control (:mod:`hexdem.waves.conical`) and the transition from the nonlinear
front to the linear regime (:mod:`hexdem.waves.transition`), and writes into ``out``:

* ``dispersion.csv`` (``path_position,kx,ky,branch,omega_theory,omega_measured,relative_deviation,
  bound,resolved,within_bound``: 1/m, 1/m, 1/m, lower/upper, rad/s, rad/s, 1, 1, true/false,
  true/false: each point's verdict against its own bound, :mod:`hexdem.waves.dispersion`) and
  ``bands.png``;
* ``conical.csv`` (``time_s,ring_radius_d,theory_radius_d``), ``control.csv``
  (``time_s,centroid_along_d,group_path_d,width_d``), ``conical.png``, ``snapshots.png`` and
  ``conical.gif``;
* ``transition.csv`` and ``transition_map.png``;
* ``dirac_point.json`` (the theory's numbers, the deviations against their bounds, the
  transition's finding) and ``dirac_point.html``, one page with all of it.

The runs' decks and initial states stay under ``runs/``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from hexdem.common.html_page import render_html
from hexdem.common.io import ensure_writable_dir, write_csv, write_json, write_text
from hexdem.theory.phonons import sound_speeds
from hexdem.waves import conical, dispersion, transition
from hexdem.waves.wave_figures import bands_figure, conical_figure, conical_movie, snapshots_figure

#: The issue's bounds: the dispersion's median relative deviation (each resolved point has its own
#: bound besides, :mod:`hexdem.waves.dispersion`), the ring's growth rate against v_D.
DISPERSION_BOUND = 0.02
SLOPE_BOUND = 0.03


@dataclass(frozen=True)
class DiracStudy:
    """The three parts' settings; :meth:`quick` the test suite's smaller case."""

    dispersion: dispersion.DispersionSettings = dispersion.DispersionSettings()
    conical: conical.ConicalSettings = conical.ConicalSettings()
    transition: transition.TransitionSettings = transition.TransitionSettings()

    @classmethod
    def quick(cls) -> DiracStudy:
        """20 per edge for 10 ms (1,141 beads), a packet of σ = 8 d to 3σ (9,577 beads), the
        transition's small sweep."""
        return cls(
            dispersion.DispersionSettings(edge_beads=20, duration_s=0.01, points_per_segment=12),
            conical.ConicalSettings(width_d=8.0, reach=3.0),
            transition.QUICK,
        )

    def on(self, engine: str, ranks: int) -> DiracStudy:
        """Every run on ``engine`` with ``ranks`` ranks."""
        return DiracStudy(
            *(replace(part, engine=engine, ranks=ranks) for part in (self.dispersion, self.conical, self.transition))
        )


def summary(measured: dispersion.Dispersion, packets: conical.Conical, sweep) -> dict:
    """dirac_point.json's contents."""
    theory = measured.theory
    c_l, c_t = sound_speeds(theory)
    omega_k = theory.dirac_frequency()
    point, branch = measured.largest_resolved()
    resolved = np.broadcast_to(measured.resolved[:, None], measured.bound.shape)
    every_resolved = bool(measured.within_bound[resolved].all())
    return {
        "precompression_n": measured.settings.precompression_n,
        "theory": {
            "spacing_m": theory.spacing_m,
            "stiffness_n_m": theory.stiffness_n_m,
            "mass_kg": theory.mass_kg,
            "dirac_omega_rad_s": omega_k,
            "dirac_frequency_hz": omega_k / (2 * math.pi),
            "cone_slope_m_s": packets.cone_slope_m_s,
            "sound_speed_longitudinal_m_s": c_l,
            "sound_speed_transverse_m_s": c_t,
        },
        "dispersion": {
            "median_relative_deviation": measured.median_deviation,
            "largest_relative_deviation": float(measured.relative_deviation.max()),
            "largest_deviation_from_gamma_per_m": measured.largest_deviation_distance_from_gamma(),
            "bound": DISPERSION_BOUND,
            "within_bound": measured.median_deviation <= DISPERSION_BOUND and every_resolved,
            "packing_width_m": measured.packing_width_m,
            "resolution_per_m": measured.resolution_per_m,
            "smallest_resolved_per_m": measured.smallest_resolved_per_m,
            "frequency_resolution_rad_s": measured.frequency_resolution_rad_s,
            "largest_resolved_relative_deviation": float(measured.relative_deviation[point, branch]),
            "largest_resolved_bound": float(measured.bound[point, branch]),
            "largest_resolved_branch": dispersion.BRANCHES[branch],
            "largest_resolved_from_gamma_per_m": float(np.linalg.norm(measured.wave_vectors[point])),
            "resolved_points": int(resolved.sum()),
            "resolved_points_within_bound": int(measured.within_bound[resolved].sum()),
            "every_resolved_point_within_bound": every_resolved,
            "settings": asdict(measured.settings),
        },
        "conical": {
            "fitted_slope_m_s": packets.fitted_slope_m_s,
            "slope_relative_deviation": packets.slope_deviation,
            "bound": SLOPE_BOUND,
            "within_bound": packets.slope_deviation <= SLOPE_BOUND,
            "control_group_velocity_m_s": packets.group_velocity_m_s,
            "control_drift_velocity_m_s": packets.drift_velocity_m_s,
            "control_drift_relative_deviation": packets.drift_deviation,
            "control_drift_bound": conical.CONTROL_DRIFT_BOUND,
            "control_widening": packets.control_widening,
            "control_widening_bound": conical.CONTROL_WIDENING_BOUND,
            "control_keeps_shape": packets.control_keeps_shape,
            "settings": asdict(packets.settings),
        },
        "transition": {"finding": sweep.finding(), "settings": asdict(sweep.settings)},
    }


def _page(result: dict) -> list:
    """The HTML page's blocks."""
    theory, spread, ring = result["theory"], result["dispersion"], result["conical"]
    a = theory["spacing_m"]
    return [
        ("h1", f"The Dirac point of the hexagonal packing precompressed at {result['precompression_n']:g} N"),
        (
            "p",
            f"Linearized about the static force, every contact is a spring of {theory['stiffness_n_m'] / 1e6:.2f} "
            f"MN/m. "
            f"The two bands meet at K at ω_K/2π = {theory['dirac_frequency_hz']:.1f} Hz in a cone of slope "
            f"v_D = {theory['cone_slope_m_s']:.2f} m/s; the long waves travel at c_L = "
            f"{theory['sound_speed_longitudinal_m_s']:.1f} and c_T = {theory['sound_speed_transverse_m_s']:.1f} m/s.",
        ),
        ("h2", "The measured dispersion"),
        (
            "p",
            f"Random velocities of every bead light up all the modes; the spectral peaks lie on the bands with a "
            f"median "
            f"relative deviation of {100 * spread['median_relative_deviation']:.2f} % (bound "
            f"{100 * spread['bound']:g} %) and a largest of {100 * spread['largest_relative_deviation']:.1f} %, at "
            f"|q| a = {spread['largest_deviation_from_gamma_per_m'] * a:.2f} from Γ.",
        ),
        (
            "p",
            f"The packing is {spread['packing_width_m'] / a:.1f} a wide: it resolves wave vectors to δq = 2π/L "
            f"(δq a = {spread['resolution_per_m'] * a:.3f}) and its record frequencies to "
            f"{spread['frequency_resolution_rad_s'] / (2 * math.pi):.0f} Hz. Beyond |q| a = "
            f"{spread['smallest_resolved_per_m'] * a:.2f} (two wavelengths across the packing) each point is bound "
            f"by its band's range within δq plus that frequency resolution. The worst there is "
            f"{100 * spread['largest_resolved_relative_deviation']:.1f} % ({spread['largest_resolved_branch']} band, "
            f"|q| a = {spread['largest_resolved_from_gamma_per_m'] * a:.2f}) against its bound of "
            f"{100 * spread['largest_resolved_bound']:.1f} %; "
            + (
                f"all {spread['resolved_points']} resolved points are within their bounds."
                if spread["every_resolved_point_within_bound"]
                else f"only {spread['resolved_points_within_bound']} of {spread['resolved_points']} resolved "
                f"points are within their bounds."
            ),
        ),
        ("figure", "bands.png", "The measured spectrum along Γ–K–M–Γ with the theory's bands drawn over it"),
        ("h2", "Conical diffraction at K"),
        (
            "p",
            f"A Gaussian packet of circularly polarized waves at K opens into a ring. Fitted with the cone's own R(t), "
            f"its growth rate is {ring['fitted_slope_m_s']:.2f} m/s, {100 * ring['slope_relative_deviation']:.2f} "
            f"% from "
            f"v_D (bound {100 * ring['bound']:g} %). The control packet away from K drifts "
            f"{100 * ring['control_drift_relative_deviation']:.2f} % from its group velocity and widens by "
            f"{100 * ring['control_widening']:.1f} %: "
            + (
                "it keeps its shape."
                if ring["control_keeps_shape"]
                else f"beyond the bounds ({100 * ring['control_drift_bound']:g} % and "
                f"{100 * ring['control_widening_bound']:g} %), it does not keep its shape."
            ),
        ),
        ("figure", "conical.png", "The ring's radius against the cone, and the control's drift"),
        ("figure", "snapshots.png", "Kinetic energy of the packet at K, and of the control at the end (log scale)"),
        ("h2", "From the nonlinear front to the linear regime"),
        ("p", result["transition"]["finding"]),
        ("figure", "transition_map.png", "The front's shape and speed over precompression and impact speed"),
    ]


def run_dirac_study(study: DiracStudy, out, log=None, show_progress: bool = True) -> dict:
    """Run the study into ``out`` (see the module docstring); returns dirac_point.json's contents."""
    out = ensure_writable_dir(out)
    log = log or (lambda message: None)
    log("dispersion: a precompressed hexagon under random velocities")
    measured = dispersion.measure_dispersion(study.dispersion, out / "runs" / "dispersion", log, show_progress)
    write_csv(out / "dispersion.csv", dispersion.COLUMNS, measured.rows())
    bands_figure(measured, out / "bands.png")
    log("conical diffraction: a packet at K and a control")
    packets = conical.measure_conical(study.conical, out / "runs" / "conical", log, show_progress)
    write_csv(out / "conical.csv", conical.COLUMNS, packets.rows())
    write_csv(out / "control.csv", conical.CONTROL_COLUMNS, packets.control_rows())
    conical_figure(packets, out / "conical.png")
    snapshots_figure(packets, out / "snapshots.png")
    conical_movie(packets, out / "conical.gif")
    log("transition: precompression against impact speed")
    sweep = transition.run_transition(study.transition, out / "runs" / "transition", log)
    write_csv(out / "transition.csv", transition.COLUMNS, sweep.rows())
    transition.transition_figure(sweep, out / "transition_map.png")
    result = summary(measured, packets, sweep)
    write_json(out / "dirac_point.json", result)
    write_text(out / "dirac_point.html", render_html(_page(result), out, "hexdem: the Dirac point"))
    return result
