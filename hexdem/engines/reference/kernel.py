"""Compiled kernel of the reference integrator: the forces of eq. (model) and classical RK4.

The paper's equations of motion (Sec. III, eq. (model)) with V(r) = (2/5) A [c − r]_+^{5/2}
give each fixed bond a repulsive force A [c − r]_+^{3/2} along the current line of centres,
where r = |rest + q_j − q_i| is the current distance of the bond's beads (rest vector
``rest`` plus displacements q) and c their contact distance. A bead touching a flat wall
with normal n feels A_w [−(g₀ + q·n)]_+^{3/2} along n (g₀ its gap at rest). Inside a curved
wall (a circle whose centre is ρ from the bead's rest position along n) the depth is exact,
−(g₀ + q·n) + (|ρn − q| − (ρ − q·n)), and the force acts along the current radius.

Layout (built by :mod:`hexdem.engines.reference.engine`): every body owns a *cell* of flat arrays. Lattice
bead {m, n} sits in the padded grid cell (n + 1)·C + (m + n)/2 + 1, so the paper's three
bond directions e₁, e₂, e₃ become three constant cell offsets and a bond's partner is a
shifted slice: the bond loop is a straight, branch-free pass over contiguous arrays that
the compiler vectorises. Cells without a bead (padding) carry bonds of stiffness 0 and
zero inverse mass. Bodies off the grid (the striker) follow the grid and are bonded
through a short explicit pair list.

Compiled with numba (``error_model="numpy"`` lets divisions vectorise) and without
fast-math, so results are IEEE-exact and reproducible.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

_jit = njit(cache=True, error_model="numpy")


class KernelArrays(NamedTuple):
    """One model laid out for the kernel, in the run's unit system.

    ``offsets`` (3,) cell offsets of the bond directions; lattice bonds start at cells
    [0, ``hi``) and beads lie in [``lo``, ``hi``). Per bond direction, (3, hi):
    ``rest_x``, ``rest_y`` rest vector from a cell to its partner, ``contact`` contact
    distance c = R_i + R_j, ``stiffness`` A = k_n sqrt(R_eff) (0: no bond). Per cell:
    ``inv_mass`` 1/M (0 for padding). Explicit pairs (i → j): ``pair_i``, ``pair_j``,
    ``pair_rest_x``, ``pair_rest_y``, ``pair_contact``, ``pair_stiffness``. Wall contacts:
    ``wall_cell``, inward normal ``wall_nx``, ``wall_ny`` at rest, rest gap ``wall_gap``,
    ``wall_curvature`` 1/ρ (0: a plane), ``wall_stiffness`` A_w = k_n,wall sqrt(R_eff). Tsuji damping (:mod:`hexdem.model.dissipation`)
    η = α sqrt(m_eff A) of each lattice bond (3, hi), explicit pair and wall contact, the damped force clipped at zero:
    ``damping``, ``pair_damping``, ``wall_damping``; ``damped`` whether any is non-zero. Per cell: ``external_x``, ``external_y`` constant
    forces (the held force of a precompressed packing's struck bead).
    """

    offsets: np.ndarray
    lo: int
    hi: int
    rest_x: np.ndarray
    rest_y: np.ndarray
    contact: np.ndarray
    stiffness: np.ndarray
    inv_mass: np.ndarray
    pair_i: np.ndarray
    pair_j: np.ndarray
    pair_rest_x: np.ndarray
    pair_rest_y: np.ndarray
    pair_contact: np.ndarray
    pair_stiffness: np.ndarray
    wall_cell: np.ndarray
    wall_nx: np.ndarray
    wall_ny: np.ndarray
    wall_gap: np.ndarray
    wall_curvature: np.ndarray
    wall_stiffness: np.ndarray
    damping: np.ndarray
    pair_damping: np.ndarray
    wall_damping: np.ndarray
    damped: bool
    external_x: np.ndarray
    external_y: np.ndarray


@_jit
def _hertz_bonds(xi, yi, xj, yj, rest_x, rest_y, contact, stiffness, fx, fy):
    """Force on bead j of each bond (i, j): A [c − r]_+^{3/2} along the line of centres."""
    for p in range(fx.shape[0]):
        dx = rest_x[p] + xj[p] - xi[p]
        dy = rest_y[p] + yj[p] - yi[p]
        r = np.sqrt(dx * dx + dy * dy)
        overlap = max(contact[p] - r, 0.0)
        f = stiffness[p] * overlap * np.sqrt(overlap) / r
        fx[p] = f * dx
        fy[p] = f * dy


@_jit
def _damped_bonds(xi, yi, xj, yj, ui, wi, uj, wj, rest_x, rest_y, contact, stiffness, damping, fx, fy):
    """As :func:`_hertz_bonds` plus Tsuji's damping η δ^{1/4} δ̇ (δ̇ > 0 while compressing), the sum
    clipped at zero (it never pulls: :mod:`hexdem.model.dissipation`)."""
    for p in range(fx.shape[0]):
        dx = rest_x[p] + xj[p] - xi[p]
        dy = rest_y[p] + yj[p] - yi[p]
        r = np.sqrt(dx * dx + dy * dy)
        overlap = max(contact[p] - r, 0.0)
        rate = -(dx * (uj[p] - ui[p]) + dy * (wj[p] - wi[p])) / r
        root = np.sqrt(overlap)
        f = max(stiffness[p] * overlap * root + damping[p] * np.sqrt(root) * rate, 0.0) / r
        fx[p] = f * dx
        fy[p] = f * dy


@_jit
def _net_bond_force(in0, in1, in2, out0, out1, out2, scale, net):
    """Net force on each cell, times ``scale``: its bonds as partner j (+) minus as origin i (−)."""
    for p in range(net.shape[0]):
        net[p] = (in0[p] + in1[p] + in2[p] - out0[p] - out1[p] - out2[p]) * scale[p]


@_jit
def _pair_forces(k, x, y, u, w, scale, fx, fy):
    for b in range(k.pair_i.shape[0]):
        i, j = k.pair_i[b], k.pair_j[b]
        dx = k.pair_rest_x[b] + x[j] - x[i]
        dy = k.pair_rest_y[b] + y[j] - y[i]
        r = np.sqrt(dx * dx + dy * dy)
        overlap = k.pair_contact[b] - r
        if overlap > 0.0:
            rate = -(dx * (u[j] - u[i]) + dy * (w[j] - w[i])) / r
            root = np.sqrt(overlap)
            f = max(k.pair_stiffness[b] * overlap * root + k.pair_damping[b] * np.sqrt(root) * rate, 0.0) / r
            fx[i] -= f * dx * scale[i]
            fy[i] -= f * dy * scale[i]
            fx[j] += f * dx * scale[j]
            fy[j] += f * dy * scale[j]


@_jit
def _wall_forces(k, x, y, u, v, scale, fx, fy):
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
            f = max(k.wall_stiffness[w] * depth * root + k.wall_damping[w] * np.sqrt(root) * rate, 0.0) * scale[c]
            fx[c] += f * nx
            fy[c] += f * ny


@_jit
def forces(k, x, y, u, w, scale, bond_fx, bond_fy, fx, fy):
    """Net force on every cell at displacements (x, y) and velocities (u, w), times ``scale``
    (1: forces; 1/M: accelerations), into (fx, fy); ``bond_fx``, ``bond_fy`` are (3, hi) scratch."""
    lo, hi = k.lo, k.hi
    for d in range(3):
        o = k.offsets[d]
        if k.damped:
            _damped_bonds(x[:hi], y[:hi], x[o:o + hi], y[o:o + hi], u[:hi], w[:hi], u[o:o + hi], w[o:o + hi],
                          k.rest_x[d], k.rest_y[d], k.contact[d], k.stiffness[d], k.damping[d],
                          bond_fx[d], bond_fy[d])
        else:
            _hertz_bonds(x[:hi], y[:hi], x[o:o + hi], y[o:o + hi], k.rest_x[d], k.rest_y[d],
                         k.contact[d], k.stiffness[d], bond_fx[d], bond_fy[d])
    o0, o1, o2 = k.offsets[0], k.offsets[1], k.offsets[2]
    for bond, net in ((bond_fx, fx), (bond_fy, fy)):
        net[:lo] = 0.0
        net[hi:] = 0.0
        _net_bond_force(bond[0, lo - o0:hi - o0], bond[1, lo - o1:hi - o1], bond[2, lo - o2:hi - o2],
                        bond[0, lo:hi], bond[1, lo:hi], bond[2, lo:hi], scale[lo:hi], net[lo:hi])
    _pair_forces(k, x, y, u, w, scale, fx, fy)
    _wall_forces(k, x, y, u, w, scale, fx, fy)
    for c in range(fx.shape[0]):
        fx[c] += k.external_x[c] * scale[c]
        fy[c] += k.external_y[c] * scale[c]


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
    """Advance displacements (x, y) and velocities (u, w) in place by ``n_steps`` RK4 steps of ``h``.

    Stage velocities (v + h/2 a₁, v + h/2 a₂, v + h a₃ of classical RK4) are formed only for a
    damped model; without damping the forces depend on positions alone.
    """
    n = x.shape[0]
    a = np.zeros((8, n))
    tx, ty = np.zeros(n), np.zeros(n)
    tu, tw = (np.zeros(n), np.zeros(n)) if k.damped else (u, w)
    bond_fx, bond_fy = np.zeros((3, k.hi)), np.zeros((3, k.hi))
    half, sq = 0.5 * h, h * h
    for _ in range(n_steps):
        forces(k, x, y, u, w, k.inv_mass, bond_fx, bond_fy, a[0], a[1])
        _stage(k, x, y, u, w, half, 0.0, a[0], a[1], a[0], a[1], tx, ty, tu, tw)
        forces(k, tx, ty, tu, tw, k.inv_mass, bond_fx, bond_fy, a[2], a[3])
        _stage(k, x, y, u, w, half, 0.25 * sq, a[0], a[1], a[2], a[3], tx, ty, tu, tw)
        forces(k, tx, ty, tu, tw, k.inv_mass, bond_fx, bond_fy, a[4], a[5])
        _stage(k, x, y, u, w, h, 0.5 * sq, a[2], a[3], a[4], a[5], tx, ty, tu, tw)
        forces(k, tx, ty, tu, tw, k.inv_mass, bond_fx, bond_fy, a[6], a[7])
        _advance(x, u, h, a[0], a[2], a[4], a[6])
        _advance(y, w, h, a[1], a[3], a[5], a[7])
