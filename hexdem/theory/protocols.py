"""Which fit protocol gives the paper's c(V₀) = m V₀ + b? A search over what Sec. V leaves open.

The paper fits :math:`V_n = V_s c^{n − s}` per V₀ and then c(V₀) = m V₀ + b, but it does not say over
which beads, which V₀, nor how. hexdem's m moves with those choices far beyond its standard
error, so a published (m, b) can only be compared with the protocol that produced it. A
**protocol** here is one choice of

* the first bead s of the per-V₀ window and its last bead;
* an **anchored** start (V_s the measured peak, the paper's reading, window s < n ≤ last) or a
  **free** one (V_s fitted with c, window s ≤ n ≤ last);
* a **log-linear** or a **nonlinear** per-V₀ fit (:func:`~hexdem.theory.scaling.fit_decay`);
* a contiguous range of the sweep's V₀ (at least :data:`MIN_V0` of them) for the line.

Every protocol is evaluated on the same peak speeds (one sweep, no new simulation): the
per-V₀ decay rates once per window and fit, then the straight line over every V₀ range at
once from prefix sums. A protocol is **consistent** with a published (m, b) when both lie
within twice hexdem's standard error plus half a unit of the published last digit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError
from hexdem.theory.scaling import FIT_KINDS, fit_decay

#: Fewest V₀ values a protocol's line c(V₀) is fitted to.
MIN_V0 = 5
#: First beads s the search tries.
STARTS = (1, 2, 3)
#: A protocol is consistent when |Δ| ≤ this many standard errors + the published rounding.
CONSISTENT_SIGMAS = 2.0
#: Columns of a protocol table (``fit_protocols.csv``).
PROTOCOL_COLUMNS = (
    "combination",
    "start",
    "last",
    "anchored",
    "fit",
    "v0_min",
    "v0_max",
    "n_v0",
    "m",
    "m_stderr",
    "b",
    "b_stderr",
    "distance",
    "consistent",
)


@dataclass(frozen=True)
class Target:
    """A published (m, b) and half a unit of each one's last published digit."""

    m: float
    b: float
    m_rounding: float
    b_rounding: float


@dataclass(frozen=True)
class ProtocolSearch:
    """Every protocol of one combination: per protocol (P,) ``start``, ``last``,
    ``anchored``, ``kind`` (index into :data:`FIT_KINDS`), V₀ index range ``first``..``final``
    (inclusive), ``m``, ``b`` and their standard errors; ``distance`` to the target, √((Δm/m)² +
    (Δb/b)²); ``consistent`` (see the module docstring); ``v0`` the sweep's V₀."""

    combination: str
    v0: np.ndarray
    start: np.ndarray
    last: np.ndarray
    anchored: np.ndarray
    kind: np.ndarray
    first: np.ndarray
    final: np.ndarray
    m: np.ndarray
    m_stderr: np.ndarray
    b: np.ndarray
    b_stderr: np.ndarray
    distance: np.ndarray
    consistent: np.ndarray

    def __len__(self) -> int:
        return len(self.m)

    def row(self, i: int) -> tuple:
        """Protocol ``i`` as a row of :data:`PROTOCOL_COLUMNS`."""
        return (
            self.combination,
            int(self.start[i]),
            int(self.last[i]),
            bool(self.anchored[i]),
            FIT_KINDS[self.kind[i]],
            float(self.v0[self.first[i]]),
            float(self.v0[self.final[i]]),
            int(self.final[i] - self.first[i] + 1),
            float(self.m[i]),
            float(self.m_stderr[i]),
            float(self.b[i]),
            float(self.b_stderr[i]),
            float(self.distance[i]),
            bool(self.consistent[i]),
        )

    def closest(self, count: int = 1) -> list[int]:
        """Indices of the ``count`` protocols nearest the target."""
        return [int(i) for i in np.argsort(self.distance, kind="stable")[:count]]

    def find(self, start: int, last: int, anchored: bool, kind: str, first: int, final: int) -> int:
        """Index of one protocol (e.g. the paper's stated one)."""
        match = np.flatnonzero(
            (self.start == start)
            & (self.last == last)
            & (self.anchored == anchored)
            & (self.kind == FIT_KINDS.index(kind))
            & (self.first == first)
            & (self.final == final)
        )
        if len(match) == 0:
            raise HexdemError(
                f"{self.combination}: no protocol with window {start}..{last}, "
                f"{'anchored' if anchored else 'free'} {kind}, V0 indices {first}..{final} was searched"
            )
        return int(match[0])

    def consistent_shares(self) -> dict:
        """Among the consistent protocols, the share of each choice (what they have in common)."""
        chosen = self.consistent
        total = int(np.count_nonzero(chosen))
        if total == 0:
            return {"count": 0}

        def share(mask) -> float:
            return round(float(np.count_nonzero(mask & chosen)) / total, 3)

        return {
            "count": total,
            "anchored": share(self.anchored),
            **{f"fit_{name}": share(self.kind == k) for k, name in enumerate(FIT_KINDS)},
            **{f"start_{s}": share(self.start == s) for s in np.unique(self.start)},
            "last_range": [int(self.last[chosen].min()), int(self.last[chosen].max())],
            "v0_min_range": [float(self.v0[self.first[chosen]].min()), float(self.v0[self.first[chosen]].max())],
            "v0_max_range": [float(self.v0[self.final[chosen]].min()), float(self.v0[self.final[chosen]].max())],
        }


def line_fits_over_ranges(x, y, min_points: int = MIN_V0):
    """Least squares y = m x + b over every contiguous range of at least ``min_points`` points.

    Returns (first, final, m, m_stderr, b, b_stderr), one entry per range [first, final].
    Sums come from prefix sums of centred data, so all ranges cost one pass.
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    xc, yc = x - x.mean(), y - y.mean()
    prefix = {
        name: np.concatenate([[0.0], np.cumsum(values)])
        for name, values in (
            ("1", np.ones_like(x)),
            ("x", xc),
            ("y", yc),
            ("xx", xc * xc),
            ("xy", xc * yc),
            ("yy", yc * yc),
        )
    }
    first, final = (a.ravel() for a in np.meshgrid(np.arange(len(x)), np.arange(len(x)), indexing="ij"))
    keep = final - first + 1 >= min_points
    first, final = first[keep], final[keep]
    s = {name: p[final + 1] - p[first] for name, p in prefix.items()}
    n = s["1"]
    spread = n * s["xx"] - s["x"] ** 2
    slope = (n * s["xy"] - s["x"] * s["y"]) / spread
    intercept_c = (s["y"] - slope * s["x"]) / n
    rss = np.maximum(s["yy"] - slope * s["xy"] - intercept_c * s["y"], 0.0)
    variance = rss / (n - 2)
    intercept = intercept_c + y.mean() - slope * x.mean()
    slope_err = np.sqrt(n * variance / spread)
    # Var(b) of the uncentred intercept: σ² Σx² / (n Σx² − (Σx)²), with Σx² taken about the origin
    sum_xx = s["xx"] + 2 * x.mean() * s["x"] + n * x.mean() ** 2
    intercept_err = np.sqrt(variance * sum_xx / spread)
    return first, final, slope, slope_err, intercept, intercept_err


def search_protocols(name: str, v0, peaks, target: Target, max_last: int, starts=STARTS) -> ProtocolSearch:
    """Every protocol of combination ``name`` on ``peaks`` (K, L): V_n of its line per V₀ of
    ``v0`` (K,), with windows ending at most at bead ``max_last``."""
    v0, peaks = np.asarray(v0, float), np.asarray(peaks, float)
    n = np.arange(peaks.shape[1])
    parts = []
    for start in starts:
        for last in range(start + 2, max_last + 1):
            for anchored in (True, False):
                for kind_index, kind in enumerate(FIT_KINDS):
                    c = np.array([fit_decay(n, row, start, last, kind, anchored)[0] for row in peaks])
                    first, final, m, m_err, b, b_err = line_fits_over_ranges(v0, c)
                    size = len(m)
                    parts.append(
                        {
                            "start": np.full(size, start),
                            "last": np.full(size, last),
                            "anchored": np.full(size, anchored),
                            "kind": np.full(size, kind_index),
                            "first": first,
                            "final": final,
                            "m": m,
                            "m_stderr": m_err,
                            "b": b,
                            "b_stderr": b_err,
                        }
                    )
    columns = {key: np.concatenate([part[key] for part in parts]) for key in parts[0]}
    distance = np.hypot((columns["m"] - target.m) / target.m, (columns["b"] - target.b) / target.b)
    consistent = (abs(columns["m"] - target.m) <= CONSISTENT_SIGMAS * columns["m_stderr"] + target.m_rounding) & (
        abs(columns["b"] - target.b) <= CONSISTENT_SIGMAS * columns["b_stderr"] + target.b_rounding
    )
    return ProtocolSearch(name, v0, distance=distance, consistent=consistent, **columns)
