r"""From the nonlinear front to the linear regime: precompression against impact speed (issue part 5).

**Physics.** In the uncompressed packing a contact carries no force until it is squeezed, so
an impulse travels as a strongly nonlinear front: faceted like the packing early on, at a speed
set by the impact itself (:math:`∝ V_0^{1/5}`, the Hertz lattice having no other scale). Under a static
force f0 per contact every contact already overlaps by :math:`δ_0 = (f_0/A)^{2/3}`; when the
impact adds an overlap small against δ0 the contacts act as springs of stiffness
:math:`k = \tfrac{3}{2} A^{2/3} f_0^{1/3}` and the front is a linear wave: it travels at the
longitudinal sound speed :math:`c_L = \sqrt{9/8}\, a \sqrt{k/m}` (a = d − δ0) and is round, the triangular spring
lattice being
isotropic at long wavelengths (:mod:`hexdem.model.precompression`).

**The overlap ratio.** The impact's own overlap is that of the first collision, two equal
spheres of mass m meeting head-on at V0: with the reduced mass m_eff = m/2, the relative
motion's energy :math:`\tfrac{1}{2} m_\text{eff} V_0^2` is all stored in the Hertz potential
:math:`\tfrac{2}{5} A δ^{5/2}` at the largest overlap, so
:math:`δ_\text{impact} = (5 m_\text{eff} V_0^2 / (4 A))^{2/5}`
(:func:`~hexdem.model.hertz.max_overlap`). δ_impact/δ0 ≪ 1 is the linear regime; an
uncompressed packing (δ0 = 0) has the ratio ∞.

**One parameter.** With overlaps far below d, measuring displacements in δ0, forces in f0 and
time in :math:`\sqrt{m δ_0 / f_0}` leaves the impact speed as
:math:`V_0 \sqrt{m/A}\, δ_0^{−5/4} ∝ (δ_\text{impact}/δ_0)^{5/4}` and nothing else: the front's speed over c_L and its
shape at a given R/d depend on
δ_impact/δ0 alone, whatever f0 (measured: the sweep's forces fall on one curve, see
``transition_map.png``). The striker's pulse is part of it: it lasts the Hertz contact time
t_c = 2.943 δ_impact/V0, a length :math:`c_L t_c ≈ 3.0\, d\, (δ_0/δ_\text{impact})^{1/4}`. Below δ_impact/δ0 ≈ 1,
where the front already travels at c_L, its small sixfold amplitude is the lattice's dispersion
acting on that pulse (short waves are not isotropic): the amplitude falls as the pulse grows
longer, seven-fold (0.0014 to 0.0002 at 25 d) between pulses of 10 and 15 d.

**Set-up and measurement.** One run per (f0, V0): a hexagon of ``edge_beads`` per edge struck at
the centre of an edge, by default by a striker bead (a smooth pulse; an initial velocity
excites every wavelength down to the spacing: measured at 20 N and 0.1 mm/s, 41 per edge, the
front's sixfold amplitude at 25 d is 0.0014 from a striker, 0.0054 from an initial velocity).
Every bead's speed is traced, and its arrival is the half-maximum of its leading pulse
(:func:`leading_arrivals`): the tracker's half-maximum of the largest speed over the run takes,
in a precompressed box, the walls' echoes for the front at a quarter of the beads within 30 d
(measured at 20 N, 41 per edge: a sixfold amplitude of 0.010 instead of 0.0018 at 20 d). The front is read over one
sixfold period of rays about the strike (±30°, :func:`~hexdem.experiments.run.measure_front_shape`);
its relative sixfold amplitude is interpolated at the mean radius ``radius_d``, and its speed is
the least-squares slope of mean radius against time between ``speed_from_d`` and ``radius_d``.
Each run lasts until a front at the faster of c_L and one layer per Hertz contact time (a
slower bound than the front itself: an uncompressed one makes about 1.5 layers) has passed
``radius_d``, plus :data:`TAIL_CONTACT_TIMES` contact times for the beads just beyond to see
their leading pulse peak and fall; the fronts read never meet a wall, no echo overtakes them
(every image source lies farther than the impact), and the front stops short of the far wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hexdem.analysis.leading_pulse import leading_maximum, parabola_vertex
from hexdem.common.checks import is_number, positive_int
from hexdem.errors import HexdemError
from hexdem.experiments.run import FRONT_WALL_MARGIN_D, measure_front_shape, simulate
from hexdem.model.config import RunConfig
from hexdem.model.hertz import contact_time, max_overlap
from hexdem.model.materials import hertz_coefficient, sphere_mass
from hexdem.model.precompression import longitudinal_sound_speed, static_overlap

#: transition.csv's columns (speed_ratio empty for an uncompressed run, which has no c_L).
COLUMNS = ("precompression_n", "v0_m_s", "overlap_ratio", "sixfold_amplitude", "front_speed_m_s", "speed_ratio")
#: The window of rays read about the strike [degrees]: one sixfold period.
WINDOW_DEG = 60.0
#: A hexagon of E per edge struck at the centre of an edge keeps the window's outermost rays
#: (±30°) inside it for this times (E − 1) d, where they meet the far walls.
WINDOW_REACH = 1.5
#: The front must be readable this far beyond ``radius_d`` [d], for the interpolation.
RADIUS_CLEARANCE_D = 5.0
#: Contact times a run goes on after its bound on the front has passed ``radius_d`` (measured at
#: 2 N, 1 mm/s, 21 per edge: after one the front is read to 17.9 d of 18, after 1.5 to 19.9 d).
TAIL_CONTACT_TIMES = 1.5
#: The finding calls a front linear while its speed is within this of c_L (measured: within
#: 0.8 % below δ_impact/δ0 = 0.1, where the pulse is long, and +1 % at 0.3).
LINEAR_SPEED_TOLERANCE = 0.02
#: The finding's mark of a clearly nonlinear front: this much faster than c_L.
NONLINEAR_SPEED_EXCESS = 0.05


@dataclass(frozen=True)
class TransitionSettings:
    """The sweep: a hexagon of ``edge_beads`` per edge under each static force of ``forces_n``
    [N per contact; 0 for the uncompressed packing], struck at each speed of ``speeds_m_s``
    [m/s]; the sixfold amplitude read at the mean front radius ``radius_d`` [bead diameters],
    the front speed fitted from ``speed_from_d`` [d] to ``radius_d`` over ``fronts`` front
    times; ``impact`` (``"striker"`` or ``"velocity"``), ``engine``, ``ranks`` and
    ``steps_per_contact`` as in :class:`~hexdem.model.config.RunConfig`.

    The defaults are the full study: 41 per edge (4,921 beads; the window is readable to 58 d),
    V0 from 0.1 mm/s to 1 m/s in half decades, uncompressed and from 0.2 to 200 N: δ_impact/δ0
    from 0.0017 to 270: 45 runs."""

    edge_beads: int = 41
    forces_n: tuple[float, ...] = (0.0, 0.2, 2.0, 20.0, 200.0)
    speeds_m_s: tuple[float, ...] = (1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0)
    radius_d: float = 25.0
    speed_from_d: float = 10.0
    fronts: int = 32
    impact: str = "striker"
    engine: str = "lammps"
    ranks: int = 1
    steps_per_contact: int = 140

    def __post_init__(self):
        positive_int("fronts", self.fronts)
        if self.fronts < 3:
            raise HexdemError(f"fronts must be at least 3 to fit a speed, got {self.fronts}")
        for name, values, low in (("forces_n", self.forces_n, "≥ 0 N"), ("speeds_m_s", self.speeds_m_s, "> 0 m/s")):
            if not isinstance(values, (tuple, list)) or not values:
                raise HexdemError(f"{name} must be a non-empty list of numbers {low}, got {values!r}")
            if not all(is_number(v) and (v >= 0 if name == "forces_n" else v > 0) for v in values):
                raise HexdemError(f"{name} must hold numbers {low}, got {list(values)!r}")
            object.__setattr__(self, name, tuple(float(v) for v in values))
        if not (is_number(self.speed_from_d) and is_number(self.radius_d) and 0 < self.speed_from_d < self.radius_d):
            raise HexdemError(f"need 0 < speed_from_d < radius_d, got {self.speed_from_d!r} and {self.radius_d!r}")
        readable = WINDOW_REACH * (positive_int("edge_beads", self.edge_beads) - 1) - FRONT_WALL_MARGIN_D
        if self.radius_d + RADIUS_CLEARANCE_D > readable:
            needed = math.ceil((self.radius_d + RADIUS_CLEARANCE_D + FRONT_WALL_MARGIN_D) / WINDOW_REACH) + 1
            raise HexdemError(
                f"radius_d {self.radius_d:g} d needs a hexagon of at least {needed} per edge, got {self.edge_beads}"
            )
        RunConfig(
            edge_beads=self.edge_beads,
            impact=self.impact,
            engine=self.engine,
            ranks=self.ranks,
            steps_per_contact=self.steps_per_contact,
        )  # its own checks, worded there

    def config(self, force_n: float, speed_m_s: float) -> RunConfig:
        """The run at ``force_n`` and ``speed_m_s``, long enough for the front to pass
        ``radius_d`` (module docstring)."""
        base = RunConfig(
            edge_beads=self.edge_beads,
            precompression_n=force_n,
            v0=speed_m_s,
            impact=self.impact,
            engine=self.engine,
            ranks=self.ranks,
            steps_per_contact=self.steps_per_contact,
        )
        d, coefficient, mass = _bead(base)
        hertz_s = float(contact_time(mass / 2, coefficient, speed_m_s))
        bound = float(np.nanmax([sound_speed(base, force_n), math.sqrt(3) / 2 * d / hertz_s]))
        return base.replace(duration=self.radius_d * d / bound + TAIL_CONTACT_TIMES * hertz_s)


QUICK = TransitionSettings(
    edge_beads=21, forces_n=(0.0, 20.0), speeds_m_s=(1e-4, 0.1), radius_d=18.0, speed_from_d=8.0, fronts=24
)
"""The test suite's and ``--quick``'s sweep: 21 per edge (1,261 beads), uncompressed and 20 N,
0.1 mm/s and 0.1 m/s."""


def _bead(config: RunConfig) -> tuple[float, float, float]:
    r"""(d [m], A [:math:`\mathrm{N/m^{1.5}}`], m [kg]) of the configuration's beads."""
    bead, d = config.material(config.bead_material), config.diameter_m
    return d, float(hertz_coefficient(d, bead)), float(sphere_mass(d, bead))


def sound_speed(config: RunConfig, force_n: float) -> float:
    """c_L [m/s] of the packing precompressed at ``force_n`` [N]; NaN uncompressed."""
    if force_n == 0:
        return float("nan")
    d, coefficient, mass = _bead(config)
    return longitudinal_sound_speed(force_n, coefficient, mass, d - static_overlap(force_n, coefficient))


def overlap_ratio(force_n: float, speed_m_s: float, coefficient: float, mass_kg: float) -> float:
    r"""δ_impact/δ0: the largest overlap of two spheres of ``mass_kg`` meeting head-on at
    ``speed_m_s`` [m/s] (m_eff = m/2, module docstring) over the static overlap at ``force_n``
    [N], for contacts of Hertz coefficient ``coefficient`` A [:math:`\mathrm{N/m^{1.5}}`]; ∞ for ``force_n`` 0."""
    impact = float(max_overlap(mass_kg / 2, coefficient, speed_m_s))
    return math.inf if force_n == 0 else impact / static_overlap(force_n, coefficient)


def _fmt(value: float) -> str:
    """A CSV field: the float's repr, NaN empty."""
    return "" if math.isnan(value) else repr(float(value))


def _short(value: float) -> str:
    """Two significant digits, a number of 100 or more written out."""
    return f"{value:.0f}" if abs(value) >= 100 else f"{value:.2g}"


@dataclass(frozen=True)
class TransitionMap:
    """The sweep's measurements, one entry per run (R,): ``forces_n`` [N], ``speeds_m_s`` [m/s],
    ``overlap_ratio`` δ_impact/δ0 (∞ uncompressed), ``sixfold_amplitude`` at ``radius_d``
    (NaN if the front was not read that far), ``front_speed_m_s`` [m/s], ``speed_ratio`` front
    speed / c_L (NaN uncompressed); ``settings``."""

    forces_n: np.ndarray
    speeds_m_s: np.ndarray
    overlap_ratio: np.ndarray
    sixfold_amplitude: np.ndarray
    front_speed_m_s: np.ndarray
    speed_ratio: np.ndarray
    settings: TransitionSettings = field(repr=False)

    def rows(self) -> list[list]:
        """transition.csv's rows (:data:`COLUMNS`), NaN as an empty field."""
        return [
            [_fmt(v) for v in run]
            for run in zip(
                self.forces_n,
                self.speeds_m_s,
                self.overlap_ratio,
                self.sixfold_amplitude,
                self.front_speed_m_s,
                self.speed_ratio,
            )
        ]

    def finding(self) -> str:
        """One sentence from the numbers, the precompressed runs taken in order of δ_impact/δ0:
        up to where their fronts travel at c_L (within :data:`LINEAR_SPEED_TOLERANCE`), from
        where they are :data:`NONLINEAR_SPEED_EXCESS` faster, and how their sixfold amplitude
        compares with the uncompressed front's."""
        pressed = self.forces_n > 0
        free = self.sixfold_amplitude[~pressed & np.isfinite(self.sixfold_amplitude)]
        if not (pressed.any() and len(free)):
            return "The sweep needs uncompressed and precompressed runs to place the transition."
        order = np.flatnonzero(pressed)[np.argsort(self.overlap_ratio[pressed], kind="stable")]
        ratio, speed, shape = self.overlap_ratio[order], self.speed_ratio[order], self.sixfold_amplitude[order]
        off = ~(np.abs(speed - 1) <= LINEAR_SPEED_TOLERANCE)  # a speed not measured (NaN) is not at c_L
        linear = int(np.argmax(off)) if off.any() else len(order)
        tolerance = f"{100 * LINEAR_SPEED_TOLERANCE:g} %"
        speeds = (
            f"travel at c_L within {tolerance} up to δ_impact/δ0 = {_short(ratio[linear - 1])}"
            if linear
            else f"are more than {tolerance} off c_L already at δ_impact/δ0 = {_short(ratio[0])}"
        )
        fast = np.flatnonzero(speed >= 1 + NONLINEAR_SPEED_EXCESS)
        if len(fast):
            speeds += (
                f", are {100 * NONLINEAR_SPEED_EXCESS:g} % faster from {_short(ratio[fast[0]])} on and reach "
                f"{np.nanmax(speed):.2f} c_L at {_short(ratio[np.nanargmax(speed)])}"
            )
        seen = np.isfinite(shape)
        if not seen.any():
            return f"Precompressed fronts {speeds}; none was read as far as {self.settings.radius_d:g} d."
        shapes = (
            f"their sixfold amplitude at {self.settings.radius_d:g} d goes from {_short(shape[seen][0])} at "
            f"{_short(ratio[seen][0])} to {_short(shape[seen][-1])} at {_short(ratio[seen][-1])}"
        )
        half = np.flatnonzero(seen & (shape >= np.median(free) / 2))
        shapes += (
            f" and passes half the uncompressed front's {_short(np.median(free))} at {_short(ratio[half[0]])}"
            if len(half)
            else f", against {_short(np.median(free))} for the uncompressed front"
        )
        return f"Precompressed fronts {speeds}; {shapes}."


def leading_arrivals(times, speeds) -> np.ndarray:
    """(B,) each bead's half-maximum arrival time of its leading pulse (the first clear hump of
    its speed, :func:`~hexdem.analysis.leading_pulse.leading_maximum`), interpolated linearly between
    the samples ``times`` (S,) of ``speeds`` (S, B); NaN for a bead without one."""
    arrivals = np.full(speeds.shape[1], np.nan)
    for bead, signal in enumerate(np.asarray(speeds, float).T):
        peak = leading_maximum(signal)
        if peak < 0:
            continue
        level = 0.5 * parabola_vertex(*signal[peak - 1 : peak + 2])
        after = int(np.argmax(signal >= level))
        if after > 0:
            fraction = (level - signal[after - 1]) / (signal[after] - signal[after - 1])
            arrivals[bead] = times[after - 1] + fraction * (times[after] - times[after - 1])
    return arrivals


def front_measures(analysis, settings: TransitionSettings) -> tuple[float, float]:
    """(sixfold amplitude at ``radius_d``, front speed [m/s]) of one run traced at every bead
    (module docstring); NaN for what the fronts read do not reach."""
    arrivals = leading_arrivals(analysis.tracked.trace_times, analysis.tracked.trace_speeds)
    shape = measure_front_shape(analysis, settings.fronts, window_deg=WINDOW_DEG, arrival_times=arrivals)
    read = np.isfinite(shape.mean_radius) & np.isfinite(shape.sixfold_amplitude)
    radius, amplitude, time = shape.mean_radius[read], shape.sixfold_amplitude[read], shape.time[read]
    sixfold = (
        float(np.interp(settings.radius_d, radius, amplitude))
        if (len(radius) and radius[0] <= settings.radius_d <= radius[-1])
        else math.nan
    )
    fitted = (radius >= settings.speed_from_d) & (radius <= settings.radius_d)
    if fitted.sum() < 3:
        return sixfold, math.nan
    slope = np.polyfit(time[fitted] * analysis.settings.units.time_s, radius[fitted], 1)[0]
    return sixfold, float(slope * analysis.model.packing.diameter_m)


def run_transition(settings: TransitionSettings, workdir, log=None) -> TransitionMap:
    """Run every (f0, V0) of ``settings`` in ``workdir``/f{f0}_v{V0} and measure its front."""
    log = log or (lambda message: None)
    workdir = Path(workdir)
    runs = [(f0, v0) for f0 in settings.forces_n for v0 in settings.speeds_m_s]
    columns = []
    for k, (f0, v0) in enumerate(runs, 1):
        config = settings.config(f0, v0)
        log(f"transition run {k}/{len(runs)}: {f0:g} N per contact, V0 = {v0:g} m/s")
        analysis = simulate(config, workdir / f"f{f0:g}_v{v0:g}", log, trace_beads=range(config.n_beads()))
        _, coefficient, mass = _bead(config)
        sixfold, speed = front_measures(analysis, settings)
        ratio = overlap_ratio(f0, v0, coefficient, mass)
        columns.append((f0, v0, ratio, sixfold, speed, speed / sound_speed(config, f0)))
        log(
            f"  δ_impact/δ0 = {ratio:.3g}, sixfold amplitude {sixfold:.3g} at {settings.radius_d:g} d, "
            f"front speed {speed:.4g} m/s ({columns[-1][-1]:.4g} c_L)"
        )
    return TransitionMap(*(np.array(column, float) for column in zip(*columns)), settings=settings)


def transition_figure(transition: TransitionMap, path) -> None:
    """Both measures against δ_impact/δ0 (log), one marker per force, the uncompressed runs at
    the right edge: the sixfold amplitude at ``radius_d`` above, the front speed over c_L below."""
    from hexdem.analysis import plotting  # matplotlib: only where figures are drawn

    ratio, settings = transition.overlap_ratio, transition.settings
    finite, free = np.isfinite(ratio), transition.forces_n == 0
    low = 10 ** math.floor(math.log10(ratio[finite].min())) if finite.any() else 0.1
    top = 10 ** math.ceil(math.log10(ratio[finite].max()) + 0.5) if finite.any() else 10.0
    x = np.where(finite, ratio, top)
    fig, (shape_ax, speed_ax) = plotting.subplots(2, 1, figsize=(7.0, 7.5), sharex=True, layout="constrained")
    markers = "osD^v<>ph"
    for k, force in enumerate(np.unique(transition.forces_n)):
        run = transition.forces_n == force
        if force == 0:
            shape_ax.plot(
                x[run],
                transition.sixfold_amplitude[run],
                "o",
                color="k",
                markersize=9,
                markerfacecolor="none",
                label="uncompressed (δ₀ = 0)",
            )
            continue
        style = {"marker": markers[k % len(markers)], "label": f"f₀ = {force:g} N per contact"}
        shape_ax.plot(x[run], transition.sixfold_amplitude[run], **style)
        speed_ax.plot(x[run], transition.speed_ratio[run], **style)
    if free.any():
        shape_ax.axhline(np.nanmedian(transition.sixfold_amplitude[free]), color="k", linestyle="--", linewidth=0.8)
        speed_ax.text(top, 1.0, "uncompressed:\nno c_L", ha="center", va="bottom", fontsize=8)
    for ax in (shape_ax, speed_ax):
        ax.set_xscale("log")
        ax.axvline(1.0, color="grey", linestyle=":", linewidth=1)
        ax.grid(True, which="major", alpha=0.3)
    shape_ax.text(1.1, 0.03, "δ_impact = δ₀", transform=shape_ax.get_xaxis_transform(), fontsize=8, color="grey")
    shape_ax.set_yscale("log")
    plotting.plain_log_ticks(shape_ax.yaxis)
    shape_ax.set_ylabel(f"sixfold amplitude of the front at R = {settings.radius_d:g} d")
    shape_ax.legend(fontsize=8, loc="lower right")
    plotting.set_title(
        shape_ax,
        f"An impact's front, nonlinear to linear: hexagon of {settings.edge_beads} per edge, {settings.impact}",
    )
    speed_ax.axhline(1.0, color="grey", linewidth=1)
    speed_ax.set_ylabel(f"front speed / c_L ({settings.speed_from_d:g} to {settings.radius_d:g} d)")
    decades = [10.0**e for e in range(round(math.log10(low)), round(math.log10(top)))]
    speed_ax.set_xticks(
        [*decades, top] if free.any() else decades,
        [*(plotting.decade_label(t) for t in decades), *(["uncompressed"] if free.any() else [])],
    )
    speed_ax.set_xlim(low / 2, top * 3)
    speed_ax.set_xlabel("δ_impact / δ₀: the impact's Hertz overlap over the static one")
    plotting.save(fig, path)
