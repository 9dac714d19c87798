"""Figures of the linear-wave study: the measured spectrum under the theory's bands, the ring
of conical diffraction against the cone, the packets' energy maps and their movie.

Frequencies are drawn as f = ω/2π in kHz and lengths in bead diameters d, the units a reader
of the experiments thinks in; the CSVs keep SI (rad/s, 1/m, s).
"""

from __future__ import annotations

import numpy as np

from hexdem.theory.phonons import PATH, band_path
from hexdem.waves.conical import Conical, PacketRun
from hexdem.waves.dispersion import Dispersion

#: The energy maps' colour scale spans this many decades below the frame's largest bead energy.
ENERGY_DECADES = 3.0


def _kilohertz(omega) -> np.ndarray:
    return np.asarray(omega) / (2 * np.pi * 1e3)


def bands_figure(dispersion: Dispersion, path) -> None:
    """The measured spectrum (each wave vector's power, scaled to its largest, on a log colour
    scale) along Γ–K–M–Γ, the theory's two bands over it, the measured peaks as dots (open short
    of the resolution limit)."""
    from matplotlib.colors import LogNorm

    from hexdem.analysis.plotting import plain_log_ticks, save, subplots

    theory = dispersion.theory
    position, _, omega = band_path(theory, 120)
    a = theory.spacing_m
    fig, ax = subplots(figsize=(7.5, 5.0), layout="constrained")
    image = ax.pcolormesh(
        dispersion.path_position * a,
        _kilohertz(dispersion.spectrum_omega),
        np.maximum(dispersion.spectrum_power, 1e-4),
        shading="nearest",
        cmap="magma",
        norm=LogNorm(1e-4, 1.0),
        rasterized=True,
    )
    bar = fig.colorbar(image, ax=ax, label="spectral power (each q scaled to its largest)")
    plain_log_ticks(bar.ax.yaxis)
    resolved = dispersion.resolved
    for branch in range(2):
        ax.plot(
            position * a,
            _kilohertz(omega[:, branch]),
            color="c",
            linewidth=1.2,
            label=r"theory: linearized Hertz, $k = \frac{3}{2} A^{2/3} f_0^{1/3}$" if branch == 0 else None,
        )
        for kept, face, edge, label in (
            (resolved, "k", "w", "measured spectral peak"),
            (
                ~resolved,
                "w",
                "k",
                f"short of the resolution limit |q| a = {dispersion.smallest_resolved_per_m * a:.2f}",
            ),
        ):
            if kept.any():
                ax.plot(
                    dispersion.path_position[kept] * a,
                    _kilohertz(dispersion.omega_measured[kept, branch]),
                    linestyle="",
                    marker="o",
                    markersize=3.5,
                    markerfacecolor=face,
                    markeredgecolor=edge,
                    label=label if branch == 0 else None,
                )
    corners = position[::120] * a
    ax.set_xticks(corners, PATH)
    for corner in corners[1:-1]:
        ax.axvline(corner, color="0.6", linewidth=0.6)
    ax.set_xlim(position[0] * a, position[-1] * a)
    ax.set_ylim(0, 1.1 * _kilohertz(omega.max()))
    ax.set_xlabel("wave vector q along Γ–K–M–Γ (distance travelled in q, times a)")
    ax.set_ylabel("frequency ω/2π [kHz]")
    settings = dispersion.settings
    point, branch = dispersion.largest_resolved()
    ax.set_title(
        f"Phonon bands of the hexagon precompressed at {settings.precompression_n:g} N "
        f"({settings.edge_beads} per edge)\ndeviation: median {100 * dispersion.median_deviation:.2f} %, "
        f"worst resolved {100 * dispersion.relative_deviation[point, branch]:.1f} % "
        f"(bound {100 * dispersion.bound[point, branch]:.1f} %)",
        fontsize=9,
    )
    fig.legend(loc="outside lower center", ncols=3, fontsize=8)
    save(fig, path)


def conical_figure(conical: Conical, path) -> None:
    """(a) The K packet's ring radius against time, the cone's R(t) for v_D, and v_D t (the
    fitted slope in the title); (b) the control: its centroid's path along its group velocity
    against the bands' prediction, and its width."""
    from hexdem.analysis.plotting import save, subplots

    d = conical.diameter_m
    fig, (left, right) = subplots(1, 2, figsize=(11, 4.4), layout="constrained")
    times_ms = conical.dirac.times_s * 1e3
    left.plot(times_ms, conical.dirac.ring_radius_m() / d, "o", markersize=4, label="measured $R(t)$")
    left.plot(times_ms, conical.theory_radius_m / d, "-", label=f"cone, $v_D$ = {conical.cone_slope_m_s:.1f} m/s")
    left.plot(times_ms, conical.cone_slope_m_s * conical.dirac.times_s / d, ":", color="0.4", label="$v_D t$")
    left.set_xlabel("time [ms]")
    left.set_ylabel("ring radius $R$ [d]")
    left.set_title(
        f"Packet at K (σ = {conical.settings.width_d:g} d): growth rate "
        f"{conical.fitted_slope_m_s / conical.cone_slope_m_s:.4f} $v_D$",
        fontsize=10,
    )
    left.legend(fontsize=8)
    control = conical.control
    speed = np.linalg.norm(conical.group_velocity_m_s)
    right.plot(control.times_s * 1e3, conical.control_path_m() / d, "o", markersize=4, label="centroid, along $v_g$")
    right.plot(control.times_s * 1e3, speed * control.times_s / d, "-", label=f"$|v_g|\\,t$, $|v_g|$ = {speed:.1f} m/s")
    right.plot(control.times_s * 1e3, conical.control_width_m / d, "s", markersize=4, label="width (rms) [d]")
    right.set_xlabel("time [ms]")
    right.set_ylabel("distance [d]")
    right.set_title(
        f"Control at {conical.settings.control_fraction:g} K, lower band: drift "
        f"{100 * conical.drift_deviation:.2f} % from $v_g$",
        fontsize=10,
    )
    right.legend(fontsize=8)
    save(fig, path)


def _energy_share(run: PacketRun, frame: int) -> np.ndarray:
    """Each bead's energy over the frame's largest, floored :data:`ENERGY_DECADES` below."""
    energies = run.recorded.block_kinetic_j[frame]
    return np.maximum(energies / energies.max(), 10.0**-ENERGY_DECADES)


#: Colour-bar label of the packets' energy maps.
ENERGY_LABEL = "kinetic energy / largest"


def _energy_axes(ax, run: PacketRun, frame: int, diameter_m: float, colorbar: bool = True):
    """Beads coloured by their share of the frame's largest energy, log scale, with its colour bar
    unless ``colorbar`` is False; the mappable."""
    from matplotlib.colors import LogNorm

    from hexdem.analysis.plotting import bead_map

    positions = (run.recorded.positions_m - run.centre_m) / diameter_m
    circles = bead_map(
        ax,
        positions,
        np.ones(len(positions)),
        _energy_share(run, frame),
        cmap="inferno",
        label=ENERGY_LABEL,
        norm=LogNorm(10.0**-ENERGY_DECADES, 1.0),
        colorbar=colorbar,
    )
    circles.set_edgecolor("none")
    ax.set_xlabel("x [d]")
    ax.set_ylabel("y [d]")
    return circles


def snapshots_figure(conical: Conical, path) -> None:
    """The K packet's energy at the start, midway and at the end, and the control's at the end:
    four panels on one colour scale, with one bar."""
    from hexdem.analysis.plotting import plain_log_ticks, save, subplots

    fig, axes = subplots(2, 2, figsize=(9.5, 8.6), layout="constrained")
    last = len(conical.dirac.times_s) - 1
    shown = [(conical.dirac, 0), (conical.dirac, last // 2), (conical.dirac, last), (conical.control, last)]
    for ax, (run, frame) in zip(axes.flat, shown):
        circles = _energy_axes(ax, run, frame, conical.diameter_m, colorbar=False)
        name = "control" if run is conical.control else "packet at K"
        ax.set_title(f"{name}, t = {run.times_s[frame] * 1e3:.2f} ms", fontsize=11)
    bar = fig.colorbar(circles, ax=axes.ravel().tolist(), label=ENERGY_LABEL, shrink=0.6)
    plain_log_ticks(bar.ax.yaxis)
    save(fig, path)


def conical_movie(conical: Conical, path) -> None:
    """GIF of the K packet's energy, block by block, as it opens into a ring."""
    from hexdem.analysis.movie import write_gif
    from hexdem.analysis.plotting import subplots

    run = conical.dirac
    fig, ax = subplots(figsize=(6.4, 5.4))
    fig.subplots_adjust(left=0.1, right=0.97, bottom=0.09, top=0.92)
    circles = _energy_axes(ax, run, 0, conical.diameter_m)
    clock = ax.text(0.5, 1.01, "", transform=ax.transAxes, ha="center", va="bottom", fontsize=12)

    def show(frame: int) -> None:
        circles.set_array(_energy_share(run, frame))
        clock.set_text(f"conical diffraction at K   t = {run.times_s[frame] * 1e3:.2f} ms")

    write_gif(fig, (circles, clock), len(run.times_s), show, path)
