"""One simulation of a design study: every candidate bead recorded at once.

A parameter set (on one packing, when disordered) is run once with every recorded bead a sensor
(:mod:`hexdem.calibration.simulations`), and each bead's record is reduced as ``hexdem calibrate``
reduces a sensor's (:mod:`hexdem.calibration.observables`): its log peak speed, and its arrival
[µs] from the impact (a design's relative arrivals are differences of these). The accelerometers'
noise is carried by a parametric bootstrap per bead: :data:`NOISE_DRAWS` copies of its record with
white noise of ``noise_m_s2`` rms on each axis, their observables' variances and covariance, on
every third parameter set (:data:`~hexdem.design.study.NOISE_EVERY`, on its first packing), the
others taking the nearest's: the noise of a small pulse's arrival depends on the pulse's shape,
which changes with the parameters.

**Sensor mass.** Every recorded bead is simulated as a plain bead (``sensor_mass_factor`` 1): one
run cannot give each of hundreds of candidates a sensor's mass without every other candidate's.
A sensor particle's extra mass changes its own and its neighbours' pulse, which a design's
criterion then leaves out; the calibrations that check a design's prediction are run with the
configured mass.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hexdem.calibration.observables import ARRIVAL_UNIT_S, at_rest_before
from hexdem.calibration.packings import PACKINGS
from hexdem.calibration.simulations import Problem, analysed_impact
from hexdem.common.io import atomic_directory, write_json
from hexdem.common.progress import silenced
from hexdem.errors import HexdemError
from hexdem.experiments.signals import integrate_velocity, pulse

#: Noisy copies of each bead's record whose observables give its noise moments.
NOISE_DRAWS = 24
#: How many times the stated noise a channel may carry (:func:`noise_moments`).
NOISE_MARGIN = 2.0
MOMENTS_NAME = "moments.npz"


def bead_observables(times, accelerations) -> np.ndarray:
    """(n, 2): each bead's log peak speed [ln(m/s)] and arrival [µs] of ``accelerations`` (n, K, 2)
    [m/s²] at ``times`` (K,) [s]; NaN where a bead holds no pulse."""
    out = np.full((len(accelerations), 2), np.nan)
    for b, channel in enumerate(accelerations):
        peak, arrival = pulse(times, *integrate_velocity(times, channel[:, 0], channel[:, 1]))
        if peak > 0 and np.isfinite(arrival):
            out[b] = np.log(peak), arrival / ARRIVAL_UNIT_S
    return out


def _bootstrap(times, accelerations, noise_m_s2: float, rng) -> np.ndarray:
    """(n, 3) moments of :func:`noise_moments` at exactly ``noise_m_s2``."""
    draws = np.array(
        [
            bead_observables(times, accelerations + noise_m_s2 * rng.standard_normal(accelerations.shape))
            for _ in range(NOISE_DRAWS)
        ]
    )
    centred = draws - np.nanmean(draws, axis=0)
    return np.column_stack(
        [
            np.nanmean(centred[:, :, 0] ** 2, axis=0),
            np.nanmean(centred[:, :, 1] ** 2, axis=0),
            np.nanmean(centred[:, :, 0] * centred[:, :, 1], axis=0),
        ]
    )


def noise_moments(times, accelerations, noise_m_s2: float, rng) -> np.ndarray:
    """(n, 3): each bead's variance of its log peak and of its arrival [µs²], and their covariance,
    under white noise of ``noise_m_s2`` rms per axis (a parametric bootstrap), as ``hexdem
    calibrate`` measures them: its bootstrap adds fresh noise to a record that holds its own, so its
    copies carry √2 times the channel's level, and so do these. A lab's channels are
    not all at the stated level: where a bead's observables degrade faster than its noise grows (a
    small pulse whose half-maximum crossing jumps from one hump to another), its moments at
    :data:`NOISE_MARGIN` times the level, scaled back by the square of the margin, are taken
    instead, so that a design does not rest on a bead that a noisier channel would lose."""
    level = np.sqrt(2.0) * noise_m_s2  # a record's own noise, and the calibration's bootstrap's on top of it
    nominal = _bootstrap(times, accelerations, level, rng)
    noisier = _bootstrap(times, accelerations, NOISE_MARGIN * level, rng) / NOISE_MARGIN**2
    worse = (noisier[:, 0] > nominal[:, 0]) | (noisier[:, 1] > nominal[:, 1])
    return np.where(worse[:, None], noisier, nominal)


def finished_moments(folder: Path, values) -> dict | None:
    """The arrays of the finished simulation in ``folder``, or None; a folder of other parameters
    is refused (the study folder holds another design)."""
    path = Path(folder) / MOMENTS_NAME
    if not path.is_file():
        return None
    with np.load(path) as data:
        arrays = {name: data[name] for name in data.files}
    if not np.allclose(arrays["values"], values, rtol=1e-12, atol=0.0):
        raise HexdemError(
            f"{folder} holds a simulation of other parameters: {Path(folder).parent.parent} holds another "
            "design; rerun the same command to resume it, or choose another --out"
        )
    return arrays


def simulate_beads(
    problem: Problem, values, folder, noise_m_s2: float, seed: int, realization: int = 0, bootstrap: bool = False
) -> None:
    """Run the parameter set ``values`` (on packing ``realization`` when disordered) with every
    bead of ``problem``'s sensors recorded, into ``folder`` (made whole or not at all): ``observables``
    (n, 2) of :func:`bead_observables` and, with ``bootstrap``, ``noise`` (n, 3) of
    :func:`noise_moments` (else NaN); a task of the study executor."""
    folder = Path(folder)
    if finished_moments(folder, values) is not None:
        return
    with atomic_directory(folder) as partial:
        partial.mkdir(parents=True)
        with silenced():
            analysis = analysed_impact(problem, values, realization, partial / "deck", folder.parent.parent / PACKINGS)
        units, tracked = analysis.settings.units, analysis.tracked
        times = tracked.sensor_times * units.time_s
        accelerations = np.moveaxis(tracked.sensor_states[:, :, 2:4], 1, 0) * (units.length_m / units.time_s**2)
        times, accelerations = at_rest_before(times, accelerations)
        rng = np.random.default_rng([seed, realization, *np.asarray(values, float).view(np.uint64).tolist()])
        write_json(partial / "parameters.json", {"keys": problem.keys, "values": [float(v) for v in values]})
        np.savez(
            partial / MOMENTS_NAME,
            values=np.asarray(values, float),
            observables=bead_observables(times, accelerations),
            noise=noise_moments(times, accelerations, noise_m_s2, rng)
            if bootstrap
            else np.full((len(accelerations), 3), np.nan),
        )
