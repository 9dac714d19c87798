"""The cubic spline through a few samples that refines peaks and crossings between them.

The same curve as ``scipy.interpolate.CubicSpline(t, y)`` with its default not-a-knot ends
(a parabola through three points, a line through two), solved here in NumPy because the
windows are tiny (at most 7 samples) and every ``hexdem run`` would otherwise import
``scipy.interpolate`` (a third of a second) for them.

Each piece is :math:`p_i(s) = a_i + b_i s + c_i s^2 + d_i s^3` with :math:`s = t − t_i` on
:math:`[t_i, t_{i+1}]`:
interpolation at both ends of every piece, continuous first and second derivatives at the
inner knots, and, with four or more points, continuous third derivatives at the second and
the second-to-last knots (not-a-knot).
"""

from __future__ import annotations

import numpy as np

#: Tolerances, relative to a piece's length: a root this far outside the piece is on its end;
#: one with an imaginary part this small is a (double) real root.
ROOT_TOLERANCE = 1e-12
IMAGINARY_TOLERANCE = 1e-8


class LocalSpline:
    """Not-a-knot cubic spline through (``times``, ``values``), 2 or more strictly increasing times."""

    def __init__(self, times, values):
        t, y = np.asarray(times, float), np.asarray(values, float)
        n = len(t)
        self.knots, self.steps = t, np.diff(t)
        pieces = n - 1
        h = self.steps
        system, rhs = np.zeros((4 * pieces, 4 * pieces)), np.zeros(4 * pieces)
        i = np.arange(pieces)
        system[2 * i, 4 * i] = 1.0  # p_i(0) = y_i
        rhs[2 * i] = y[:-1]
        for power in range(4):  # p_i(h_i) = y_{i+1}
            system[2 * i + 1, 4 * i + power] = h**power
        rhs[2 * i + 1] = y[1:]
        j, row = i[:-1], 2 * pieces + 2 * i[:-1]
        system[row, 4 * j + 1], system[row, 4 * j + 2], system[row, 4 * j + 3] = 1.0, 2 * h[j], 3 * h[j] ** 2
        system[row, 4 * j + 5] = -1.0  # p_i'(h_i) = p_{i+1}'(0)
        system[row + 1, 4 * j + 2], system[row + 1, 4 * j + 3] = 2.0, 6 * h[j]
        system[row + 1, 4 * j + 6] = -2.0  # p_i''(h_i) = p_{i+1}''(0)
        row = 4 * pieces - 2
        if n >= 4:  # not-a-knot: one cubic across each of the two outer inner knots
            system[row, [3, 7]] = (1.0, -1.0)
            system[row + 1, [4 * pieces - 5, 4 * pieces - 1]] = (1.0, -1.0)
        elif n == 3:  # a parabola through three points
            system[row, 3], system[row + 1, 7] = 1.0, 1.0
        else:  # a line through two
            system[row, 2], system[row + 1, 3] = 1.0, 1.0
        self.coefficients = np.linalg.solve(system, rhs).reshape(pieces, 4)

    def __call__(self, t) -> np.ndarray:
        t = np.asarray(t, float)
        i = np.clip(np.searchsorted(self.knots, t, side="right") - 1, 0, len(self.steps) - 1)
        s = t - self.knots[i]
        a, b, c, d = self.coefficients[i].T
        return a + s * (b + s * (c + s * d))

    def stationary_points(self) -> np.ndarray:
        """Times where the derivative b + 2c s + 3d s² vanishes, within the knots (a root of
        a near-double pair counts once or twice: either is a stationary point)."""
        a, b, c, d = self.coefficients.T
        quadratic, linear, constant = 3 * d, 2 * c, b
        found = []
        with np.errstate(divide="ignore", invalid="ignore"):
            discriminant = linear**2 - 4 * quadratic * constant
            root = np.sqrt(np.maximum(discriminant, 0.0))
            q = -0.5 * (linear + np.copysign(root, linear))
            curved = np.abs(quadratic) * self.steps > ROOT_TOLERANCE * np.abs(linear)
            candidates = np.where(
                curved[:, None],
                np.column_stack([q / quadratic, constant / q]),
                np.column_stack([-constant / linear, np.full_like(linear, np.nan)]),
            )
        real = ~curved | (discriminant >= -IMAGINARY_TOLERANCE * np.abs(linear) ** 2)
        for i in np.flatnonzero(real):
            found += self._on_piece(i, candidates[i])
        return np.array(sorted(found))

    def crossings(self, level: float, piece: int | None = None) -> np.ndarray:
        """Times where the spline equals ``level``, within the knots (or only on ``piece``)."""
        pieces = range(len(self.steps)) if piece is None else [piece]
        found = []
        for i in pieces:
            a, b, c, d = self.coefficients[i]
            coefficients = np.array([d, c, b, a - level])
            nonzero = np.flatnonzero(coefficients)
            if len(nonzero) < 2:
                continue
            roots = np.roots(coefficients[nonzero[0] :])
            found += self._on_piece(i, roots[np.abs(roots.imag) <= IMAGINARY_TOLERANCE * self.steps[i]].real)
        return np.array(sorted(found))

    def _on_piece(self, i: int, roots) -> list[float]:
        """Times of the local roots s that lie on piece i (its ends within round-off)."""
        h = self.steps[i]
        return [
            float(self.knots[i] + min(max(s, 0.0), h))
            for s in np.asarray(roots, float)
            if np.isfinite(s) and -ROOT_TOLERANCE * h <= s <= h * (1 + ROOT_TOLERANCE)
        ]
