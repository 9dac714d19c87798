"""How round a wavefront is: its polar radius R(θ) about the impact and R's sixfold harmonic.

The front at time t is the iso-line "arrival time = t" of the beads' half-maximum arrival
times. Early on it is faceted like the hexagonal packing, later it may become circular. The
measure is the least-squares fit R(θ) ≈ a0 + a6 cos 6θ + b6 sin 6θ and its relative sixfold
amplitude sqrt(a6² + b6²) / a0: 0 for a circle, :data:`HEXAGON_SIXFOLD` for a regular hexagon,
independent of the front's orientation.

R(θ) is read along ``n_bins`` rays from the impact point (θ from +x, radians, at the centres
of equal angular bins): arrival times are interpolated linearly on the Delaunay triangulation
of the beads whose time is known (NaN beads are left out), and R is the first radius along the
ray where that field rises past t. Unlike regressing r on t over the beads inside each bin,
this recovers a circle exactly and a hexagon's amplitude to within the rays' sampling of its
corners (−0.3 % at 144 rays). Lengths are in the positions' unit (callers pass bead diameters).

**Walls, direction by direction.** A ray is read only until the front comes within
``wall_margin`` of where the ray leaves the packing: beyond, the front has met the wall in that
direction and what it does there is the wall's. The other rays go on, so the front is followed
until fewer than 60° of rays (one sixfold period) are left, not only until it first meets a
wall: in a hexagon struck at the centre of an edge the walls beside the struck edge come at
0.43 of the edge length, the far wall at 1.73.

**A fixed window.** As rays drop out one by one, the fit's angular range shrinks and what it
measures changes (a front from an edge impact has other harmonics than the sixth, which alias
differently over different ranges). ``window_deg`` keeps the range fixed instead: only the rays
within ±``window_deg``/2 of +x (into the packing from its left edge) are fitted, and a front
counts only while all of them see it. A window of 60° is one sixfold period: a regular hexagon
keeps its amplitude there, and a 60°-periodic front is measured as on the whole circle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError

#: Rays (angular bins) around the full circle by default: 2.5° apart.
DEFAULT_BINS = 144
#: Fewest rays that keep cos 6θ from aliasing onto a lower harmonic (harmonic n − 6 ≠ 0..6).
MIN_BINS = 13
#: Samples along each ray; the crossing is interpolated between them.
RAY_SAMPLES = 1024
#: Beads lie on one line when their positions' second principal spread is below this fraction of
#: the first (round-off of the packed positions is ~1e-16 of it).
COLLINEAR_TOLERANCE = 1e-9
#: A regular hexagon's relative sixfold amplitude, 2 − 32 / (15 ln 3), from the Fourier
#: coefficients of R(θ) = R_in / cos φ over φ in [−30°, 30°]: a0 = (3/π) ln 3 · R_in and
#: abs(a6) = (6/π) (ln 3 − 16/15) · R_in.
HEXAGON_SIXFOLD = 2.0 - 32.0 / (15.0 * np.log(3.0))
#: Header of the front-shape table (mean radius in bead diameters).
FRONT_SHAPE_COLUMNS = ("time", "mean_radius_d", "sixfold_amplitude", "bins_used")


@dataclass(frozen=True)
class FrontShape:
    """One value per front time, each an (n_times,) array; NaN where too few rays met the front.

    ``sixfold_cos`` and ``sixfold_sin`` are a6/a0 and b6/a0 with their signs (the amplitude is
    their norm): a6 > 0 puts the front's six farthest points at 0° and every 60° from it (+x, the
    strike of an edge impact), a6 < 0 its six faces there.
    """

    time: np.ndarray
    mean_radius: np.ndarray
    sixfold_amplitude: np.ndarray
    bins_used: np.ndarray
    sixfold_cos: np.ndarray
    sixfold_sin: np.ndarray

    def rows(self) -> list[tuple]:
        """Rows following :data:`FRONT_SHAPE_COLUMNS`."""
        return [
            (float(t), float(r), float(a), int(n))
            for t, r, a, n in zip(self.time, self.mean_radius, self.sixfold_amplitude, self.bins_used)
        ]


@dataclass(frozen=True)
class _Rays:
    """Arrival time along each ray: ``theta`` (n_bins,), ``radius`` (n_samples,), ``time`` (n_bins, n_samples),
    and ``extent`` (n_bins,): the radius at which each ray leaves the beads whose arrival is known
    (NaN for a ray outside them)."""

    theta: np.ndarray
    radius: np.ndarray
    time: np.ndarray
    extent: np.ndarray

    def usable(self, wall_margin: float) -> np.ndarray:
        """(n_bins, n_samples) mask of the samples at least ``wall_margin`` inside the packing."""
        return self.radius[None, :] <= (self.extent - wall_margin)[:, None]


def _checked(positions, arrival_times, origin):
    """Bead positions relative to ``origin`` (n, 2) and arrival times (n,), or HexdemError."""
    positions, arrival_times, origin = (np.asarray(a, float) for a in (positions, arrival_times, origin))
    if positions.ndim != 2 or positions.shape[1] != 2 or origin.shape != (2,):
        raise HexdemError(f"positions must be (n, 2) and origin (2,), got {positions.shape} and {origin.shape}")
    if arrival_times.shape != (len(positions),):
        raise HexdemError(f"{len(positions)} positions but arrival times of shape {arrival_times.shape}")
    return positions - origin, arrival_times


def linear_field(points, values):
    """f(xi): ``values`` interpolated linearly on the Delaunay triangles of ``points`` (n, 2), NaN
    outside their hull: what ``scipy.interpolate.LinearNDInterpolator`` computes, without
    importing ``scipy.interpolate`` into every run (nor ``scipy.spatial``, a slow import, into the
    modules that import this one: it loads here)."""
    from scipy.spatial import Delaunay

    triangulation = Delaunay(points)
    values = np.asarray(values, float)

    def field(xi):
        xi = np.asarray(xi, float)
        flat = xi.reshape(-1, 2)
        simplex = triangulation.find_simplex(flat)
        transform = triangulation.transform[simplex]
        weights = np.einsum("ijk,ik->ij", transform[:, :2], flat - transform[:, 2])
        weights = np.column_stack([weights, 1.0 - weights.sum(axis=1)])
        result = np.sum(weights * values[triangulation.simplices[simplex]], axis=1)
        result[simplex < 0] = np.nan
        return result.reshape(xi.shape[:-1])

    return field


def front_unmeasurable(positions, arrival_times) -> str | None:
    """Why no front can be read from these arrivals, or None when it can: the front is a curve in
    the plane, interpolated over the triangles of the beads whose arrival is known, so it needs
    three of them or more, not all on one line (a chain, a single bead or a pair has none)."""
    known = np.asarray(positions, float)[np.isfinite(np.asarray(arrival_times, float))]
    if len(known) < 3:
        return f"a 2D front needs arrival times at 3 beads or more, not on one line; known at {len(known)}"
    spread = np.linalg.svd(known - known.mean(axis=0), compute_uv=False)
    if spread[1] <= COLLINEAR_TOLERANCE * spread[0]:
        return f"a 2D front needs arrival times at beads not all on one line; the {len(known)} known lie on one"
    return None


def _rays(positions, arrival_times, origin, n_bins) -> _Rays:
    if int(n_bins) != n_bins or n_bins < MIN_BINS:
        raise HexdemError(f"n_bins must be an integer >= {MIN_BINS} to resolve a sixfold shape, got {n_bins}")
    relative, arrival_times = _checked(positions, arrival_times, origin)
    if (reason := front_unmeasurable(relative, arrival_times)) is not None:
        raise HexdemError(reason)
    from scipy.spatial import QhullError

    known = np.isfinite(arrival_times)
    try:
        field = linear_field(relative[known], arrival_times[known])
    except (QhullError, ValueError):
        raise HexdemError(f"arrival times known at {known.sum()} beads do not span a triangle: no front") from None
    theta = -np.pi + (np.arange(int(n_bins)) + 0.5) * 2 * np.pi / n_bins
    radius = np.linspace(0.0, np.hypot(*relative[known].T).max(), RAY_SAMPLES)
    directions = np.column_stack([np.cos(theta), np.sin(theta)])
    time = field(radius[None, :, None] * directions[:, None, :])
    inside = np.isfinite(time)
    last = len(radius) - 1 - np.argmax(inside[:, ::-1], axis=1)
    extent = np.where(inside.any(axis=1), radius[last], np.nan)
    return _Rays(theta, radius, time, extent)


def _crossings(rays: _Rays, time: float, wall_margin: float = 0.0) -> np.ndarray:
    """First radius along each ray where the arrival time rises past ``time``, at least
    ``wall_margin`` inside the packing; NaN if it never does."""
    usable = rays.usable(wall_margin)
    before, after = rays.time[:, :-1], rays.time[:, 1:]
    rising = (before <= time) & (after > time) & usable[:, 1:]
    hit = np.flatnonzero(rising.any(axis=1))
    k = np.argmax(rising[hit], axis=1)
    fraction = (time - before[hit, k]) / (after[hit, k] - before[hit, k])
    radius = np.full(len(rays.theta), np.nan)
    radius[hit] = rays.radius[k] + fraction * (rays.radius[1] - rays.radius[0])
    return radius


def front_radius(positions, arrival_times, origin, time, n_bins=DEFAULT_BINS):
    """(θ, R): ray angles (radians from +x about ``origin``) and the front's radius along each at ``time``.

    R is NaN along rays where the front is not bracketed at ``time`` (not yet past the
    impact point, already beyond the packing, or beyond the beads the wave reached).
    """
    rays = _rays(positions, arrival_times, origin, n_bins)
    return rays.theta, _crossings(rays, time)


def sixfold_roundness(theta, radius) -> tuple[float, float]:
    """(a0, sqrt(a6² + b6²)/a0) of R(θ) ≈ a0 + a6 cos 6θ + b6 sin 6θ, fitted over the finite R
    (see :func:`sixfold_components`)."""
    a0, a6, b6 = sixfold_components(theta, radius)
    return a0, float(np.hypot(a6, b6) / a0)


def sixfold_components(theta, radius) -> tuple[float, float, float]:
    """(a0, a6, b6) of R(θ) ≈ a0 + a6 cos 6θ + b6 sin 6θ, fitted over the finite R.

    Least squares handles a front seen over part of the circle (half a plane for an edge
    impact). Returns NaNs when the finite bins cannot determine the three coefficients (fewer
    than four, or rank-deficient): a front time without a usable front.
    """
    theta, radius = np.asarray(theta, float), np.asarray(radius, float)
    if theta.shape != radius.shape or theta.ndim != 1:
        raise HexdemError(f"theta and radius must be matching 1-D arrays, got {theta.shape} and {radius.shape}")
    finite = np.isfinite(radius) & np.isfinite(theta)
    basis = np.column_stack([np.ones(finite.sum()), np.cos(6 * theta[finite]), np.sin(6 * theta[finite])])
    if finite.sum() < 4 or np.linalg.matrix_rank(basis) < 3:
        return float("nan"), float("nan"), float("nan")
    a0, a6, b6 = np.linalg.lstsq(basis, radius[finite], rcond=None)[0]
    return float(a0), float(a6), float(b6)


def _window(rays: _Rays, window_deg: float | None) -> np.ndarray:
    """Mask of the rays within ±``window_deg``/2 of +x (all rays for None)."""
    if window_deg is None:
        return np.ones(len(rays.theta), dtype=bool)
    return np.abs(rays.theta) <= np.radians(window_deg) / 2


def front_shape(
    positions, arrival_times, origin, times, n_bins=DEFAULT_BINS, min_bins=None, wall_margin=0.0, window_deg=None
) -> FrontShape:
    """Mean radius and sixfold amplitude of the front at each of ``times``.

    Each ray is read up to ``wall_margin`` from where it leaves the packing; with
    ``window_deg``, only the rays of that window about +x are used. Times at which fewer than
    ``min_bins`` rays (default ``n_bins // 6``: 60°, one sixfold period; with a window, all of
    its rays) meet the front get NaN radius and amplitude (a front of mean radius 0, NaN
    amplitude); ``bins_used`` counts those rays.
    """
    rays = _rays(positions, arrival_times, origin, n_bins)
    window = _window(rays, window_deg)
    if min_bins is None:
        min_bins = int(n_bins) // 6 if window_deg is None else int(window.sum())
    times = np.atleast_1d(np.asarray(times, float))
    mean, cos6, sin6 = (np.full(len(times), np.nan) for _ in range(3))
    used = np.zeros(len(times), int)
    for i, time in enumerate(times):
        radius = np.where(window, _crossings(rays, time, wall_margin), np.nan)
        used[i] = np.isfinite(radius).sum()
        if used[i] >= min_bins:
            mean[i], a6, b6 = sixfold_components(rays.theta, radius)
            if mean[i] > 0:  # (a front not round the origin, a flat striker's, may have none)
                cos6[i], sin6[i] = a6 / mean[i], b6 / mean[i]
    return FrontShape(times, mean, np.hypot(cos6, sin6), used, cos6, sin6)


def front_times(
    positions,
    arrival_times,
    origin,
    count=8,
    start_quantile=0.05,
    n_bins=DEFAULT_BINS,
    wall_margin=0.0,
    geometric=False,
    window_deg=None,
) -> np.ndarray:
    """``count`` front times from early on to the last time the front can be read over 60°.

    Start: the ``start_quantile`` quantile of the known arrival times, so the front is already a
    few beads across rather than the struck bead's neighbourhood. End: the latest time at which
    ``n_bins // 6`` rays (60°, one sixfold period) still see the front at least ``wall_margin``
    inside the packing (:func:`front_shape`): each ray's last readable time is the arrival time
    where it comes within ``wall_margin`` of the packing's edge; with ``window_deg``, the latest
    time at which every ray of that window still does (:func:`front_shape`). Evenly spaced, or
    evenly in log time (``geometric``: as many fronts per factor of radius near the impact as
    far away).
    """
    relative, arrival_times = _checked(positions, arrival_times, origin)
    known = np.isfinite(arrival_times)
    if known.sum() < 3:
        raise HexdemError(f"arrival times known at only {known.sum()} beads, too few for a front")
    start = np.quantile(arrival_times[known], start_quantile)
    rays = _rays(positions, arrival_times, origin, n_bins)
    readable = np.where(rays.usable(wall_margin) & np.isfinite(rays.time), rays.time, -np.inf).max(axis=1)
    needed = int(n_bins) // 6 if window_deg is None else int(_window(rays, window_deg).sum())
    latest = readable[_window(rays, window_deg)]
    # just before the needed-th ray's last readable time: that ray still brackets the front
    last = np.nextafter(np.sort(latest)[::-1][needed - 1], -np.inf)
    if not last > start:
        raise HexdemError(f"the front cannot be read over 60° after t = {last:.4g}, before the start time {start:.4g}")
    return np.geomspace(start, last, count) if geometric else np.linspace(start, last, count)
