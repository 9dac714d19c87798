"""Priors of ``hexdem calibrate``: ``--prior KEY=DIST``, one per calibrated parameter.

``KEY`` is a numeric key of the run configuration, or a dotted path into its tables
(``materials.steel316.youngs_modulus_pa``, ``impacts.0.v0``: :func:`~hexdem.experiments.sweep_plan.with_value`).
``DIST`` is ``uniform(a, b)``, ``loguniform(a, b)`` (0 < a < b) or ``normal(mu, sigma)``.

The inference works in the unit cube: every prior maps its parameter θ to u = F(θ), F its
cumulative distribution, so that the prior is uniform on [0, 1]^p whatever the distributions
and a sampler needs no Jacobian. A normal prior is cut at :data:`NORMAL_TAIL` standard
deviations on either side (a mass of 6e-5 is lost), so that every u maps to a finite θ.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError

DISTRIBUTIONS = ("uniform", "loguniform", "normal")
#: A normal prior is truncated at mu ± NORMAL_TAIL sigma.
NORMAL_TAIL = 4.0
_PATTERN = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_.]*)\s*=\s*([a-z]+)\s*\(\s*([^,()]+)\s*,\s*([^,()]+)\s*\)\s*$")


@dataclass(frozen=True)
class Prior:
    """The prior of one parameter ``key``: ``kind`` (one of :data:`DISTRIBUTIONS`) with the two
    numbers that define it, ``a`` and ``b`` (bounds, or mu and sigma), in the key's own units."""

    key: str
    kind: str
    a: float
    b: float

    def __post_init__(self):
        if self.kind not in DISTRIBUTIONS:
            raise HexdemError(f"--prior {self.key}: unknown distribution {self.kind!r}; use {', '.join(DISTRIBUTIONS)}")
        if not (math.isfinite(self.a) and math.isfinite(self.b)):
            raise HexdemError(f"--prior {self.key}: its numbers must be finite, got {self.a!r}, {self.b!r}")
        if self.kind == "normal" and not self.b > 0:
            raise HexdemError(f"--prior {self.key}: normal(mu, sigma) needs sigma > 0, got {self.b!r}")
        if self.kind != "normal" and not self.a < self.b:
            raise HexdemError(f"--prior {self.key}: {self.kind}(a, b) needs a < b, got {self.a!r}, {self.b!r}")
        if self.kind == "loguniform" and not self.a > 0:
            raise HexdemError(f"--prior {self.key}: loguniform(a, b) needs a > 0, got {self.a!r}")

    @classmethod
    def parse(cls, text: str) -> Prior:
        """``KEY=DIST`` → a prior; a malformed one is one clear line."""
        match = _PATTERN.match(text)
        if not match:
            raise HexdemError(
                f"--prior {text!r}: expected KEY=uniform(a, b), KEY=loguniform(a, b) or KEY=normal(mu, sigma)"
            )
        key, kind, a, b = match.groups()
        try:
            return cls(key, kind, float(a), float(b))
        except ValueError:
            raise HexdemError(f"--prior {text!r}: {a.strip()!r} or {b.strip()!r} is not a number") from None

    def _frozen(self):
        from scipy import stats  # a second of import: only where a prior is mapped, not in a simulation's worker

        if self.kind == "uniform":
            return stats.uniform(self.a, self.b - self.a)
        if self.kind == "loguniform":
            return stats.loguniform(self.a, self.b)
        return stats.truncnorm(-NORMAL_TAIL, NORMAL_TAIL, loc=self.a, scale=self.b)

    @property
    def support(self) -> tuple[float, float]:
        """The smallest and largest value the prior gives."""
        if self.kind == "normal":
            return self.a - NORMAL_TAIL * self.b, self.a + NORMAL_TAIL * self.b
        return self.a, self.b

    def from_unit(self, u) -> np.ndarray:
        """θ of the unit-cube coordinate ``u`` (the prior's quantile function)."""
        return self._frozen().ppf(np.asarray(u, float))

    def to_unit(self, value) -> np.ndarray:
        """u = F(θ) of the parameter ``value``."""
        return self._frozen().cdf(np.asarray(value, float))

    def describe(self) -> str:
        return f"{self.kind}({self.a:g}, {self.b:g})"

    def as_dict(self) -> dict:
        return {"distribution": self.kind, "a": self.a, "b": self.b, "text": self.describe()}


def parse_priors(texts) -> list[Prior]:
    """The priors of the ``--prior`` options, each key once."""
    priors = [Prior.parse(text) for text in texts]
    if not priors:
        raise HexdemError("a calibration needs at least one --prior KEY=DIST")
    keys = [prior.key for prior in priors]
    if len(set(keys)) != len(keys):
        raise HexdemError(f"--prior: a key is given twice ({', '.join(keys)})")
    return priors


def to_parameters(priors, unit) -> np.ndarray:
    """Parameters θ (n, p) of unit-cube points ``unit`` (n, p)."""
    unit = np.atleast_2d(unit)
    return np.column_stack([prior.from_unit(unit[:, j]) for j, prior in enumerate(priors)])
