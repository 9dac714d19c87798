r"""Initial states that excite linear waves, as per-bead velocities and displacements [SI].

* :func:`broadband_state`: independent Gaussian velocities of every bead, white in wave vector
  and polarization: every mode of the packing gets energy, the whole band structure lights up.
* :func:`bloch_packet`: a Gaussian envelope of width σ on one Bloch mode (q, e, ω) of the
  theory, :math:`u = \operatorname{Re}[(V/ω)\, G(r)\, e\, e^{i(q \cdot (r − c) − ωt)}]` at t = 0, so
  :math:`u = (V/ω)\, G \operatorname{Re}(e\, e^{iφ})` and :math:`v = V G \operatorname{Im}(e\, e^{iφ})`
  with φ = q·(r − c), G = exp(−|r − c|²/2σ²): a packet of the waves near (q, +ω) only, its peak speed V. The
  polarization e (a unit 2-vector) may be complex: at the Dirac point, where both polarizations
  share ω_K, the circular e = (1, i)/√2 is the one whose packet does not drift
  (:mod:`hexdem.waves.conical`).
"""

from __future__ import annotations

import numpy as np


def broadband_state(n_beads: int, speed_m_s: float, seed: int) -> np.ndarray:
    """(N, 2) velocities [m/s], each component normal with standard deviation ``speed_m_s``,
    reproducible from ``seed``."""
    return speed_m_s * np.random.default_rng(seed).standard_normal((n_beads, 2))


def bloch_packet(
    positions_m, centre_m, width_m: float, wave_vector_m, polarization, omega_rad_s: float, speed_m_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """(velocities [m/s], displacements [m]), each (N, 2), of the packet of the module docstring
    centred on ``centre_m`` with envelope width ``width_m`` (σ)."""
    offsets = np.asarray(positions_m, float) - np.asarray(centre_m, float)
    envelope = np.exp(-np.sum(offsets**2, axis=1) / (2 * width_m**2))
    wave = np.exp(1j * offsets @ np.asarray(wave_vector_m, float))[:, None] * np.asarray(polarization, complex)[None, :]
    shape = speed_m_s * envelope[:, None]
    return shape * wave.imag, shape / omega_rad_s * wave.real
