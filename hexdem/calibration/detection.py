"""The chance that the sensors detect a packing's pulse, as a function of the parameters.

On disordered packings a sensor may record noise alone: the pulse took another path past it, or
waited at a gap the settling left. Such records are left out, and so are the simulated packings
whose pulse stays below the records' detection level (:mod:`~hexdem.calibration.observables`,
:func:`~hexdem.calibration.simulations.detected`). The records kept are then a selection, and
how many were kept is itself a measurement: of R_d records detected and R_u left out, the
likelihood holds

    R_d log P(u) + R_u log(1 − P(u)),

with P(u) the chance that a packing's pulse reaches every sensor above its detection level at the
parameters u. P is emulated (:class:`~hexdem.calibration.emulator.Emulator`) on the logit of each
parameter set's detected share of its K packings, (k + ½)/(K + 1) (Jeffreys' estimate, finite at
0 and K), smooth along σ as the spread is. Where every simulated packing is detected P stays near
1 and the term changes nothing; where the records lost as many packings as the simulations do at
some parameters and not at others, it tells them apart.
"""

from __future__ import annotations

import numpy as np
from scipy.special import expit, logit

from hexdem.calibration.emulator import Emulator
from hexdem.calibration.spread import NOISY_NUGGET, level_groups


class Detection:
    """P(u), fitted to simulations at unit-cube ``points`` (n, p) with ``observables`` (n, K, m) (NaN
    for a packing whose pulse the sensors do not detect); ``smooth``, the dimensions along which
    it is smooth over the whole prior (:class:`~hexdem.calibration.emulator.Emulator`)."""

    def __init__(self, points, observables, smooth=()):
        detected = np.isfinite(np.asarray(observables, float)[..., 0])
        realizations = detected.shape[1]
        self.always = bool(detected.all())
        if not self.always:
            share = (detected.sum(axis=1) + 0.5) / (realizations + 1)
            groups = level_groups(points, smooth)
            self.emulator = Emulator(
                points, logit(share)[:, None], nugget_max=NOISY_NUGGET, smooth=smooth, groups=groups
            )

    def probability(self, unit) -> np.ndarray:
        """P (k,) at unit-cube points ``unit`` (k, p): 1 where every simulated packing was detected."""
        unit = np.atleast_2d(unit)
        if self.always:
            return np.ones(len(unit))
        return expit(self.emulator.predict(unit)[0][:, 0])

    def log_likelihood(self, unit, detected: int, undetected: int) -> np.ndarray:
        """R_d log P + R_u log(1 − P) (k,) at ``unit``, of ``detected`` records kept and ``undetected`` left out."""
        probability = self.probability(unit)
        if self.always:
            return np.zeros(len(probability))
        return detected * np.log(probability) + undetected * np.log1p(-probability)
