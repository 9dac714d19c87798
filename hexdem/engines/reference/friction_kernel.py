"""Compiled kernel of the reference integrator with friction: Hertz–Mindlin contacts and spinning spheres.

Selected by the contact law's data (:mod:`hexdem.model.contact_law`) when any contact has a
tangential force; the frictionless kernel (:mod:`hexdem.engines.reference.kernel`) is untouched.
Every contact is in an explicit list: a pair of bodies (i, j) of the neighbour list
(:mod:`hexdem.engines.reference.neighbours`) with rest vector, contact distance c = R_i + R_j,
A = k_n sqrt(R_eff), Tsuji's η, K = k_t sqrt(R_eff) (Mindlin's k_t a = K sqrt(δ)), μ and the radii;
or a body on a wall, with the wall's geometry as in the frictionless kernel. As there,
:func:`integrate_frictional` stops before a step where the list has gone stale, for the engine
to rebuild it; the histories ξ of the pairs in both lists are carried over by their (i, j) keys.

The law is LAMMPS's ``tangential mindlin`` in 2D. With n the unit vector from i to j (a wall's
inward normal) and t = ẑ × n, the contact points slip at
s = (v_j − v_i)·t − (R_i ω_i + R_j ω_j)   (a body on a wall: s = v·t − R ω),
the tangential displacement ξ (a scalar along t, which turns with the contact: LAMMPS's history
rotated into the tangent plane with its length kept) grows as ξ' = s, and is set to 0 at the start of
every step that finds the bodies apart (so that it counts the slip since they touched, within a step,
as LAMMPS's history created by the step that finds the contact), and the tangential force is
f = K sqrt(δ) ξ, −f t on j and +f t on i (−f t on a body on a wall), capped at μ F_n (F_n with its
damping, clipped at zero as LAMMPS's ``limit_damping`` clips it: it never pulls, and where the damping
would make it pull the cap is 0): on slip ξ is set back to the capped force's displacement.
Torques: +(R_i − δ/2) f on i and +(R_j − δ/2) f on j (LAMMPS's levers, which add up to the distance of the centres, so
that
angular momentum is kept), +R f on a body on a wall. Moment of inertia of a solid sphere,
I = (2/5) m R².

Time integration: classical RK4 of (q, v, ω, ξ); the cap is applied to the force at every stage and
to the state ξ at the start of each step (as LAMMPS applies it at each force evaluation).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from hexdem.engines.reference.kernel import _advance, _jit, _shifted, stale


class FrictionArrays(NamedTuple):
    """One frictional model laid out for the kernel, in the run's unit system.

    Pairs (b = 0 … P−1): ``pair_i``, ``pair_j`` bodies, ``pair_rest_x``, ``pair_rest_y`` rest vector
    i → j, ``pair_contact`` c, ``pair_stiffness`` A, ``pair_damping`` η, ``pair_tangential`` K,
    ``pair_mu`` μ, ``pair_radius_i``, ``pair_radius_j``. Walls: ``wall_cell``, ``wall_nx``, ``wall_ny``,
    ``wall_gap``, ``wall_curvature`` (as in :class:`~hexdem.engines.reference.kernel.KernelArrays`),
    ``wall_stiffness``, ``wall_damping``, ``wall_tangential``, ``wall_mu``, ``wall_radius``. Per body:
    ``inv_mass`` 1/m, ``inv_inertia`` 1/I, ``external_x``, ``external_y``, ``built_x``, ``built_y``
    (the displacements at the list's build) and ``reach``, as in the frictionless kernel.
    """

    pair_i: np.ndarray
    pair_j: np.ndarray
    pair_rest_x: np.ndarray
    pair_rest_y: np.ndarray
    pair_contact: np.ndarray
    pair_stiffness: np.ndarray
    pair_damping: np.ndarray
    pair_tangential: np.ndarray
    pair_mu: np.ndarray
    pair_radius_i: np.ndarray
    pair_radius_j: np.ndarray
    wall_cell: np.ndarray
    wall_nx: np.ndarray
    wall_ny: np.ndarray
    wall_gap: np.ndarray
    wall_curvature: np.ndarray
    wall_stiffness: np.ndarray
    wall_damping: np.ndarray
    wall_tangential: np.ndarray
    wall_mu: np.ndarray
    wall_radius: np.ndarray
    inv_mass: np.ndarray
    inv_inertia: np.ndarray
    external_x: np.ndarray
    external_y: np.ndarray
    built_x: np.ndarray
    built_y: np.ndarray
    reach: float


@_jit
def _capped(tangential, root, normal, mu, xi, cap):
    """(f, ξ) of Mindlin's force f = K sqrt(δ) ξ capped at μ F_n (F_n >= 0, clipped); ``cap``: also set
    ξ back on slip."""
    stiffness = tangential * root
    force = stiffness * xi
    limit = mu * normal
    if abs(force) > limit:
        force = limit if force > 0.0 else -limit
        if cap:
            xi = force / stiffness
    return force, xi


@_jit
def _pairs(k, x, y, u, w, spin, xi, cap, fx, fy, torque, slip):
    for b in range(k.pair_i.shape[0]):
        i, j = k.pair_i[b], k.pair_j[b]
        dx = k.pair_rest_x[b] + x[j] - x[i]
        dy = k.pair_rest_y[b] + y[j] - y[i]
        r = np.sqrt(dx * dx + dy * dy)
        nx, ny = dx / r, dy / r
        overlap = k.pair_contact[b] - r
        du, dw = u[j] - u[i], w[j] - w[i]
        slip[b] = ny * -du + nx * dw - (k.pair_radius_i[b] * spin[i] + k.pair_radius_j[b] * spin[j])
        if overlap <= 0.0:
            if cap:
                xi[b] = 0.0
            continue
        root = np.sqrt(overlap)
        normal = max(
            k.pair_stiffness[b] * overlap * root - k.pair_damping[b] * np.sqrt(root) * (nx * du + ny * dw), 0.0
        )
        f, xi[b] = _capped(k.pair_tangential[b], root, normal, k.pair_mu[b], xi[b], cap)
        gx, gy = normal * nx + f * ny, normal * ny - f * nx  # on j: F_n n − f t, t = (−n_y, n_x)
        fx[i] -= gx
        fy[i] -= gy
        fx[j] += gx
        fy[j] += gy
        torque[i] += (k.pair_radius_i[b] - 0.5 * overlap) * f
        torque[j] += (k.pair_radius_j[b] - 0.5 * overlap) * f


@_jit
def _wall_depth(k, w, x, y):
    """(depth, n_x, n_y) of wall contact ``w`` at the displacements (x, y): the frictionless kernel's
    overlap and inward normal (exact inside a circle, along the current radius). Its lines stay
    inline in the frictionless kernel, whose speed the call would cost (docs/validation/benchmarks.md,
    *Figures behind choices in the code*)."""
    c = k.wall_cell[w]
    nx, ny = k.wall_nx[w], k.wall_ny[w]
    along = x[c] * nx + y[c] * ny
    depth = -(k.wall_gap[w] + along)
    kappa = k.wall_curvature[w]
    if kappa != 0.0:
        ax, ay = nx - kappa * x[c], ny - kappa * y[c]
        reach = np.sqrt(ax * ax + ay * ay)
        depth += (reach - (1.0 - kappa * along)) / kappa
        nx, ny = ax / reach, ay / reach
    return depth, nx, ny


@_jit
def _walls(k, x, y, u, v, spin, xi, cap, fx, fy, torque, slip):
    for c in range(k.wall_cell.shape[0]):
        cell = k.wall_cell[c]
        depth, nx, ny = _wall_depth(k, c, x, y)
        slip[c] = -ny * u[cell] + nx * v[cell] - k.wall_radius[c] * spin[cell]
        if depth <= 0.0:
            if cap:
                xi[c] = 0.0
            continue
        root = np.sqrt(depth)
        normal = max(
            k.wall_stiffness[c] * depth * root - k.wall_damping[c] * np.sqrt(root) * (u[cell] * nx + v[cell] * ny), 0.0
        )
        f, xi[c] = _capped(k.wall_tangential[c], root, normal, k.wall_mu[c], xi[c], cap)
        fx[cell] += normal * nx + f * ny  # F_n n − f t
        fy[cell] += normal * ny - f * nx
        torque[cell] += k.wall_radius[c] * f


@_jit
def frictional_forces(k, x, y, u, w, spin, pair_xi, wall_xi, cap, fx, fy, torque, pair_slip, wall_slip):
    """Forces (fx, fy) and torques on every body, and the slip rates of every contact, at the state
    (q, v, ω, ξ); ``cap``: also set the histories ξ back to the Coulomb cap in place."""
    for c in range(fx.shape[0]):
        fx[c] = k.external_x[c]
        fy[c] = k.external_y[c]
        torque[c] = 0.0
    _pairs(k, x, y, u, w, spin, pair_xi, cap, fx, fy, torque, pair_slip)
    _walls(k, x, y, u, w, spin, wall_xi, cap, fx, fy, torque, wall_slip)


@_jit
def _scale(values, factors):
    for c in range(values.shape[0]):
        values[c] *= factors[c]


@_jit
def _rates(k, x, y, u, w, spin, pair_xi, wall_xi, cap, out, pair_slip, wall_slip):
    """Accelerations (out[0], out[1]), angular accelerations (out[2]) and slip rates at one stage."""
    frictional_forces(k, x, y, u, w, spin, pair_xi, wall_xi, cap, out[0], out[1], out[2], pair_slip, wall_slip)
    _scale(out[0], k.inv_mass)
    _scale(out[1], k.inv_mass)
    _scale(out[2], k.inv_inertia)


@_jit
def _first_order(z, h, k1, k2, k3, k4):
    """Classical RK4 update of z' = f: z += h/6 (k1 + 2 k2 + 2 k3 + k4)."""
    for c in range(z.shape[0]):
        z[c] += h / 6.0 * (k1[c] + 2.0 * k2[c] + 2.0 * k3[c] + k4[c])


@_jit
def integrate_frictional(k, x, y, u, w, spin, pair_xi, wall_xi, h, n_steps):
    """Advance displacements (x, y), velocities (u, w), spins ω and the contacts' histories ξ in place
    by up to ``n_steps`` RK4 steps of ``h``; returns the steps done, fewer when the neighbour list went
    :func:`~hexdem.engines.reference.kernel.stale` first."""
    n, p, m = x.shape[0], pair_xi.shape[0], wall_xi.shape[0]
    a = np.zeros((4, 3, n))
    ps, ws = np.zeros((4, p)), np.zeros((4, m))
    tx, ty, tu, tw, ts = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    tp, tq = np.zeros(p), np.zeros(m)
    steps, shifts = (0.5 * h, 0.5 * h, h), (0.0, 0.25 * h * h, 0.5 * h * h)
    # run-time bools: a literal True or False would give _rates a compiled variant of its own for
    # each, beside the one for the bool that Python's calls of frictional_forces pass
    capped, free = np.bool_(True), np.bool_(False)
    for step in range(n_steps):
        if stale(k, x, y):
            return step
        _rates(k, x, y, u, w, spin, pair_xi, wall_xi, capped, a[0], ps[0], ws[0])
        for s in range(3):  # stages 2-4: q + cv v + ca a, and z + cv z' for v, ω and ξ
            cv, ca = steps[s], shifts[s]
            prev = a[s]
            older = a[s - 1] if s > 0 else a[0]  # the position stage takes the acceleration before last
            _shifted(tx, x, cv, u, ca, older[0])
            _shifted(ty, y, cv, w, ca, older[1])
            _shifted(tu, u, cv, prev[0], 0.0, prev[0])
            _shifted(tw, w, cv, prev[1], 0.0, prev[1])
            _shifted(ts, spin, cv, prev[2], 0.0, prev[2])
            _shifted(tp, pair_xi, cv, ps[s], 0.0, ps[s])
            _shifted(tq, wall_xi, cv, ws[s], 0.0, ws[s])
            _rates(k, tx, ty, tu, tw, ts, tp, tq, free, a[s + 1], ps[s + 1], ws[s + 1])
        _advance(x, u, h, a[0, 0], a[1, 0], a[2, 0], a[3, 0])
        _advance(y, w, h, a[0, 1], a[1, 1], a[2, 1], a[3, 1])
        _first_order(spin, h, a[0, 2], a[1, 2], a[2, 2], a[3, 2])
        _first_order(pair_xi, h, ps[0], ps[1], ps[2], ps[3])
        _first_order(wall_xi, h, ws[0], ws[1], ws[2], ws[3])
    return n_steps
