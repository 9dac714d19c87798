r"""Compiled kernel of the reference integrator: the forces of eq. (4) and classical RK4.

The paper's equations of motion (Sec. III, eq. (4)) with
:math:`V(r) = \tfrac{2}{5} A\, [c − r]_+^{5/2}` give each pair of bodies a repulsive force
:math:`A\, [c − r]_+^{3/2}` along the current line of centres, where
:math:`r = \left|\text{rest} + q_j − q_i\right|` is the current distance of the pair (rest vector
``rest`` between their positions at t = 0 plus displacements q) and c their contact distance. A bead
touching a flat wall with normal n feels :math:`A_w\, [−(g_0 + q \cdot n)]_+^{3/2}` along n (g₀ its
gap at rest). Inside a curved wall (a circle whose centre is ρ from the bead's rest position along
n) the depth is exact, :math:`−(g_0 + q \cdot n) + (\left|ρn − q\right| − (ρ − q \cdot n))`, and the
force acts along the current radius.

The pairs are the neighbour list's (:mod:`hexdem.engines.reference.neighbours`): every pair whose
gap was below the skin at the list's build, sorted by i, then j. A listed pair that does not touch
adds nothing, so the forces do not depend on when the list was built. :func:`integrate` checks
before every step whether a body has moved more than ``reach`` since the build and stops there,
for the engine to rebuild the list.

Compiled with numba (``error_model="numpy"`` lets divisions vectorise) and without
fast-math, so results are IEEE-exact and reproducible.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

_jit = njit(cache=True, error_model="numpy")


class KernelArrays(NamedTuple):
    """One model and its neighbour list laid out for the kernel, in the run's unit system.

    Listed pairs (i → j, b = 0 … P−1): ``pair_i``, ``pair_j`` bodies, ``pair_rest_x``,
    ``pair_rest_y`` rest vector i → j (of their positions at t = 0), ``pair_contact`` contact
    distance c = R_i + R_j, ``pair_stiffness`` A = k_n sqrt(R_eff). Wall contacts: ``wall_cell``
    the body, inward normal ``wall_nx``, ``wall_ny`` at rest, rest gap ``wall_gap``,
    ``wall_curvature`` 1/ρ (0: a plane), ``wall_stiffness`` A_w = k_n,wall sqrt(R_eff). Tsuji damping
    (:mod:`hexdem.model.dissipation`) η = α sqrt(m_eff A) of each pair and wall contact, the damped
    force clipped at zero: ``pair_damping``, ``wall_damping``; ``damped`` whether any is non-zero.
    Per body: ``inv_mass`` 1/M, ``external_x``, ``external_y`` constant forces (the held force of a
    precompressed packing's struck bead), ``built_x``, ``built_y`` its displacement at the list's
    build; ``reach`` how far a body may move from there before the list must be rebuilt.
    """

    pair_i: np.ndarray
    pair_j: np.ndarray
    pair_rest_x: np.ndarray
    pair_rest_y: np.ndarray
    pair_contact: np.ndarray
    pair_stiffness: np.ndarray
    pair_damping: np.ndarray
    wall_cell: np.ndarray
    wall_nx: np.ndarray
    wall_ny: np.ndarray
    wall_gap: np.ndarray
    wall_curvature: np.ndarray
    wall_stiffness: np.ndarray
    wall_damping: np.ndarray
    damped: bool
    inv_mass: np.ndarray
    external_x: np.ndarray
    external_y: np.ndarray
    built_x: np.ndarray
    built_y: np.ndarray
    reach: float


@_jit
def stale(k, x, y):
    """Whether a body at displacements (x, y) has moved more than ``k.reach`` since the neighbour
    list's build (at ``k.built_x``, ``k.built_y``): the list must be rebuilt."""
    limit = k.reach * k.reach
    for c in range(x.shape[0]):
        dx = x[c] - k.built_x[c]
        dy = y[c] - k.built_y[c]
        if dx * dx + dy * dy > limit:
            return True
    return False


@_jit
def _pair_forces(k, x, y, u, w, fx, fy):
    r"""Add the force of every touching listed pair: :math:`A δ^{3/2}`, plus Tsuji's
    :math:`η δ^{1/4} \dot{δ}` (:math:`\dot{δ} > 0` while compressing) in a damped model, the sum
    clipped at zero (it never pulls)."""
    for b in range(k.pair_i.shape[0]):
        i, j = k.pair_i[b], k.pair_j[b]
        dx = k.pair_rest_x[b] + x[j] - x[i]
        dy = k.pair_rest_y[b] + y[j] - y[i]
        r = np.sqrt(dx * dx + dy * dy)
        overlap = k.pair_contact[b] - r
        if overlap > 0.0:
            root = np.sqrt(overlap)
            if k.damped:
                rate = -(dx * (u[j] - u[i]) + dy * (w[j] - w[i])) / r
                f = max(k.pair_stiffness[b] * overlap * root + k.pair_damping[b] * np.sqrt(root) * rate, 0.0) / r
            else:
                f = k.pair_stiffness[b] * overlap * root / r
            fx[i] -= f * dx
            fy[i] -= f * dy
            fx[j] += f * dx
            fy[j] += f * dy


@_jit
def _wall_forces(k, x, y, u, v, fx, fy):
    for w in range(k.wall_cell.shape[0]):
        c = k.wall_cell[w]
        nx, ny = k.wall_nx[w], k.wall_ny[w]
        along = x[c] * nx + y[c] * ny
        depth = -(k.wall_gap[w] + along)
        kappa = k.wall_curvature[w]
        if kappa != 0.0:  # the circle's centre is at ρn: depth from the distance to it, direction along it
            ax, ay = nx - kappa * x[c], ny - kappa * y[c]
            reach = np.sqrt(ax * ax + ay * ay)  # |ρn − q| / ρ
            depth += (reach - (1.0 - kappa * along)) / kappa
            nx, ny = ax / reach, ay / reach
        if depth > 0.0:
            rate = -(u[c] * nx + v[c] * ny)
            root = np.sqrt(depth)
            f = max(k.wall_stiffness[w] * depth * root + k.wall_damping[w] * np.sqrt(root) * rate, 0.0)
            fx[c] += f * nx
            fy[c] += f * ny


@_jit
def forces(k, x, y, u, w, scale, fx, fy):
    """Net force on every body at displacements (x, y) and velocities (u, w), times ``scale``
    (1: forces; 1/M: accelerations), into (fx, fy)."""
    for c in range(fx.shape[0]):
        fx[c] = k.external_x[c]
        fy[c] = k.external_y[c]
    _pair_forces(k, x, y, u, w, fx, fy)
    _wall_forces(k, x, y, u, w, fx, fy)
    for c in range(fx.shape[0]):
        fx[c] *= scale[c]
        fy[c] *= scale[c]


@_jit
def _shifted(out, q, cv, v, ca, a):
    """out = q + cv·v + ca·a: a position (or velocity) at which an RK4 stage evaluates the force."""
    for c in range(out.shape[0]):
        out[c] = q[c] + cv * v[c] + ca * a[c]


@_jit
def _stage(k, x, y, u, w, cv, ca, ax, ay, bx, by, tx, ty, tu, tw):
    """An RK4 stage's state: positions (tx, ty) = q + cv·v + ca·a, and, for a damped model whose
    forces depend on velocity, velocities (tu, tw) = v + cv·b."""
    _shifted(tx, x, cv, u, ca, ax)
    _shifted(ty, y, cv, w, ca, ay)
    if k.damped:
        _shifted(tu, u, cv, bx, 0.0, bx)
        _shifted(tw, w, cv, by, 0.0, by)


@_jit
def _advance(q, v, h, a1, a2, a3, a4):
    """Classical RK4 update of q'' = a(q): q += h v + h²/6 (a1+a2+a3), v += h/6 (a1+2a2+2a3+a4)."""
    for c in range(q.shape[0]):
        q[c] += h * v[c] + h * h / 6.0 * (a1[c] + a2[c] + a3[c])
        v[c] += h / 6.0 * (a1[c] + 2.0 * a2[c] + 2.0 * a3[c] + a4[c])


@_jit
def integrate(k, x, y, u, w, h, n_steps):
    """Advance displacements (x, y) and velocities (u, w) in place by up to ``n_steps`` RK4 steps
    of ``h``; returns the steps done, fewer when the neighbour list went :func:`stale` first.

    Stage velocities (v + h/2 a₁, v + h/2 a₂, v + h a₃ of classical RK4) are formed only for a
    damped model; without damping the forces depend on positions alone.
    """
    n = x.shape[0]
    a = np.zeros((8, n))
    tx, ty = np.zeros(n), np.zeros(n)
    tu, tw = (np.zeros(n), np.zeros(n)) if k.damped else (u, w)
    half, sq = 0.5 * h, h * h
    for step in range(n_steps):
        if stale(k, x, y):
            return step
        forces(k, x, y, u, w, k.inv_mass, a[0], a[1])
        _stage(k, x, y, u, w, half, 0.0, a[0], a[1], a[0], a[1], tx, ty, tu, tw)
        forces(k, tx, ty, tu, tw, k.inv_mass, a[2], a[3])
        _stage(k, x, y, u, w, half, 0.25 * sq, a[0], a[1], a[2], a[3], tx, ty, tu, tw)
        forces(k, tx, ty, tu, tw, k.inv_mass, a[4], a[5])
        _stage(k, x, y, u, w, h, 0.5 * sq, a[2], a[3], a[4], a[5], tx, ty, tu, tw)
        forces(k, tx, ty, tu, tw, k.inv_mass, a[6], a[7])
        _advance(x, u, h, a[0], a[2], a[4], a[6])
        _advance(y, w, h, a[1], a[3], a[5], a[7])
    return n_steps
