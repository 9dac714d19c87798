"""Where a wave packet's energy is: its centroid, its spread and its ring radius, from each
bead's (block-averaged) energy as weight (:mod:`hexdem.analysis.wave_recorder`).

* centroid c(t) = Σ E_j r_j / Σ E_j;
* spread W(t) = sqrt(Σ E_j |r_j − c(t)|² / Σ E_j), the rms distance from the centroid;
* ring radius R(t) = sqrt(⟨r²⟩(t) − ⟨r²⟩(0)) about a fixed centre c0, ⟨r²⟩ = Σ E_j |r_j − c0|² / Σ E_j,
  with ⟨r²⟩(0) that of a Gaussian envelope G_j = exp(−|r_j − c0|²/2σ²) on the same beads
  (energy ∝ G²): for a packet that opens into a ring of radius ρ much wider than σ, R → ρ.
"""

from __future__ import annotations

import numpy as np


def energy_centroid(positions, energies) -> np.ndarray:
    """(F, 2) centroid of each row of ``energies`` (F, N) over ``positions`` (N, 2)."""
    energies = np.asarray(energies, float)
    return energies @ np.asarray(positions, float) / energies.sum(axis=1)[:, None]


def energy_spread(positions, energies, centroids) -> np.ndarray:
    """(F,) rms distance of each row's energy from its centroid (F, 2)."""
    offsets = np.asarray(positions, float)[None, :, :] - np.asarray(centroids, float)[:, None, :]
    energies = np.asarray(energies, float)
    return np.sqrt(np.sum(energies * np.sum(offsets**2, axis=2), axis=1) / energies.sum(axis=1))


def ring_radius(positions, energies, centre, width) -> np.ndarray:
    """(F,) R(t) of the module docstring about ``centre`` for a packet of envelope width ``width`` (σ)."""
    squared = np.sum((np.asarray(positions, float) - np.asarray(centre, float)) ** 2, axis=1)
    energies = np.asarray(energies, float)
    start_weights = np.exp(-squared / width**2)
    start = np.sum(start_weights * squared) / np.sum(start_weights)
    return np.sqrt(np.maximum(energies @ squared / energies.sum(axis=1) - start, 0.0))
