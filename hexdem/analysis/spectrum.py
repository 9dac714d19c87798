"""Spectra in time of recorded plane-wave components, and their peaks: the measured dispersion.

A plane wave of the linear lattice, u ∝ e cos(q·r − ωt), puts the frequency ω into the lattice
Fourier sum V(q, t) of :mod:`hexdem.analysis.wave_recorder`. Projected on a polarization e_b(q)
(the theory's eigenvector of branch b), V gives one branch's signal, whose power spectrum
peaks at that branch's ω_b(q). The spectrum here is:

* **windowed** (Hann) against the leakage of a record that starts and stops abruptly;
* **zero-padded** ``pad`` times, a finer grid for the peak's refinement;
* **folded**: the power at −ω added to that at +ω (the field is real, a wave of q appears at
  −ω in the sum of −q), so ω ≥ 0.

The peak is the largest bin above ``lowest`` refined by a parabola through the logarithm of
the power at it and its two neighbours: exact for a Gaussian line, and for the Hann window's
main lobe within a small fraction of a bin.

**Bands by polarization.** Projected on e_b alone, a strong line of the other band still puts
into branch b the share of its power along e_b: a mode of the finite packing is a mixture of
wave vectors near q, whose polarizations differ from e_b(q), most near Γ where the bands'
polarizations turn with the direction of q. :func:`band_peaks` therefore gives each frequency
bin to the band whose polarization holds the larger share of its power, and each band's peak is
its largest bin among its own: a lower-band point is never measured at an upper-band line.
"""

from __future__ import annotations

import numpy as np

from hexdem.errors import HexdemError


def branch_signals(components, polarizations) -> np.ndarray:
    """(S, Q, B) e_b(q) · V(q, t): ``components`` (S, Q, 2) projected on ``polarizations``
    (Q, 2, B), each column a unit vector."""
    return np.einsum("sqa,qab->sqb", np.asarray(components), np.asarray(polarizations))


def power_spectrum(times_s, signals, pad: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """(ω [rad/s] (W,), power (W, ...)) of ``signals`` (S, ...) sampled evenly at ``times_s``
    (see the module docstring); ω runs from 0 to the Nyquist frequency."""
    times_s, signals = np.asarray(times_s, float), np.asarray(signals)
    if len(signals) != len(times_s):
        raise HexdemError(f"a spectrum needs one signal row per time, got {len(signals)} rows for {len(times_s)} times")
    if len(times_s) < 8:
        raise HexdemError(f"a spectrum needs at least 8 evenly spaced samples, got {len(times_s)}")
    interval = times_s[1] - times_s[0]
    window = np.hanning(len(times_s)).reshape((-1,) + (1,) * (signals.ndim - 1))
    n = pad * len(times_s)
    transform = np.fft.fft((signals - signals.mean(axis=0)) * window, n=n, axis=0)
    power = np.abs(transform) ** 2
    half = n // 2
    folded = power[: half + 1].copy()
    folded[1:half] += power[n - 1 : n - half : -1]
    return 2 * np.pi * np.arange(half + 1) / (n * interval), folded


def peak_frequency(omega, power, lowest: float = 0.0, allowed=None) -> np.ndarray:
    """The refined peak ω of each column of ``power`` (W, ...) over ``omega`` (W,), among the
    bins above ``lowest`` [rad/s] and, if given, where ``allowed`` (W, ..., bool) holds (see
    the module docstring)."""
    omega, power = np.asarray(omega, float), np.asarray(power, float)
    shape = power.shape[1:]
    columns = power.reshape(len(omega), -1)
    inside = np.flatnonzero(omega > lowest)
    inside = inside[(inside > 0) & (inside < len(omega) - 1)]
    if not len(inside):
        raise HexdemError(f"no frequency of the spectrum lies above {lowest:g} rad/s and below its last")
    candidates = columns[inside]
    if allowed is not None:
        allowed = np.asarray(allowed, bool).reshape(columns.shape)[inside]
        if not allowed.any(axis=0).all():
            raise HexdemError("a spectrum has no allowed frequency for its peak")
        candidates = np.where(allowed, candidates, -np.inf)
    peaks = inside[np.argmax(candidates, axis=0)]
    span = np.arange(columns.shape[1])
    left, middle, right = (
        np.log(np.maximum(columns[peaks + shift, span], np.finfo(float).tiny)) for shift in (-1, 0, 1)
    )
    curvature = left - 2 * middle + right
    shift = np.where(curvature < 0, 0.5 * (left - right) / np.where(curvature < 0, curvature, -1.0), 0.0)
    return (omega[peaks] + shift * (omega[1] - omega[0])).reshape(shape)


def band_peaks(omega, power) -> np.ndarray:
    """(..., B) each band's refined peak ω [rad/s]: ``power`` (W, ..., B) the spectra of the B
    branch signals (:func:`branch_signals`), each bin counted for the band that holds the larger
    share of its power (see the module docstring)."""
    power = np.asarray(power, float)
    return peak_frequency(omega, power, allowed=power >= power.max(axis=-1, keepdims=True))
