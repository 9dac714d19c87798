r"""Reference integrator of the paper's Hamiltonian (Sec. III): an engine independent of LAMMPS.

It integrates eq. (4) as the paper does, with classical 4th-order Runge–Kutta:

* contacts found from the bodies' positions, as in LAMMPS: a neighbour search
  (:mod:`hexdem.engines.reference.neighbours`) lists the pairs whose gap is below a skin, and is
  run again whenever a body has moved half the skin; each touching pair (gap below 0) has
  :math:`V(r) = \tfrac{2}{5} A\, [c − r]_+^{5/2}`: no tension, a per-pair contact distance
  :math:`c = R_i + R_j` and :math:`A = k_n \sqrt{R_\text{eff}}`, so any packing and per-bead
  diameters work (for equal beads c = d and A is the paper's A); contacts open and close during
  a run;
* the Hertz force along the *current* line of centres, :math:`r = \left|\text{rest} + q_j − q_i\right|`;
* flat walls as sphere–half-plane Hertz contacts with the wall's own modulus
  (:math:`F = k_{n,\text{wall}} \sqrt{R}\, δ^{3/2}`, the paper's "spheres with an infinite
  radius"), acting on the wall's member beads only, so the struck bead sits in the impact hole as in the decks;
* each impact's V0 on its bead, or on a striker sphere, a body like the beads for the
  neighbour search.

It works in the run's unit system (SI, or the paper's A = d = M = 1 of eq. (3)) and
hands its samples, taken like a LAMMPS dump's, to the same observer as LAMMPS, so the same
analysis judges both engines. In a triangular packing the list at t = 0 is exactly the lattice's
six touching neighbours (the paper's e₁, e₂, e₃): its next-nearest neighbours are further apart
than the skin.

The force and RK4 loops are compiled (:mod:`hexdem.engines.reference.kernel`, numba). A model whose
contact law has a tangential force (friction) runs instead on the frictional kernel, with spins and
contact histories (:mod:`hexdem.engines.reference.friction`); the engine picks the kernel from the law.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path

import numpy as np

from hexdem.common.checks import is_number, positive_int
from hexdem.common.io import write_json
from hexdem.common.progress import progress_bar
from hexdem.engines.reference.contacts import ListedPairs, PairLaws, coefficient, wall_geometry
from hexdem.engines.reference.friction import FrictionalSystem
from hexdem.engines.reference.kernel import KernelArrays, forces, integrate
from hexdem.engines.sampling import Observer, Sample
from hexdem.errors import HexdemError
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.units import UnitSystem

#: Description of the run written into the engine's directory.
PARAMETERS_NAME = "reference.json"


def _wall_contacts(model: GranularModel, units: UnitSystem) -> dict:
    """The kernel's wall fields of every wall member: sphere–wall Hertz
    (:func:`~hexdem.engines.reference.contacts.wall_geometry`), A_w = k_n,wall sqrt(R_eff)."""
    beads, normals, gaps, curvature, r_eff = wall_geometry(model)
    stiffness = coefficient(model.wall_stiffness_pa(beads) if model.walls else np.zeros(0), r_eff, units)
    damping = model.wall_damping * np.sqrt(model.masses_kg[beads] / units.mass_kg * stiffness)
    return dict(
        wall_cell=beads.astype(np.int64),
        wall_nx=normals[:, 0].copy(),
        wall_ny=normals[:, 1].copy(),
        wall_gap=gaps / units.length_m,
        wall_curvature=curvature * units.length_m,
        wall_stiffness=stiffness,
        wall_damping=damping,
    )


@dataclass
class ReferenceSystem:
    """A frictionless :class:`GranularModel` in ``units`` for :mod:`hexdem.engines.reference.kernel`:
    its walls and the pairs of its neighbour list (``pairs``, rebuilt during the integration)."""

    pairs: ListedPairs
    units: UnitSystem

    @classmethod
    def from_model(cls, model: GranularModel, units: UnitSystem) -> ReferenceSystem:
        laws = PairLaws.of(model, units)

        def fields(i, j) -> dict:
            rest_x, rest_y, contact, stiffness, damping = laws.normal(i, j)
            return dict(
                pair_rest_x=rest_x,
                pair_rest_y=rest_y,
                pair_contact=contact,
                pair_stiffness=stiffness,
                pair_damping=damping,
            )

        external = model.external_forces_n() / units.force_n
        body = dict(
            **_wall_contacts(model, units),
            damped=model.dissipative,
            inv_mass=units.mass_kg / model.masses_kg,
            external_x=external[:, 0].copy(),
            external_y=external[:, 1].copy(),
        )
        return cls(ListedPairs.at_rest(laws, fields, lambda **listed: KernelArrays(**listed, **body)), units)

    @property
    def kernel(self) -> KernelArrays:
        return self.pairs.kernel

    @property
    def n_wall_contacts(self) -> int:
        return len(self.kernel.wall_cell)

    def angular_velocities(self) -> None:
        """The bodies' spins: none, frictionless spheres never turn."""
        return None

    def forces(self, displacements) -> np.ndarray:
        """(n_bodies, 2) net Hertz force on every body at ``displacements``, at rest (both in
        ``units``), the list rebuilt there."""
        x, y = (np.array(column, float) for column in np.asarray(displacements, float).T)
        self.pairs.rebuild(x, y)
        fx, fy = np.zeros_like(x), np.zeros_like(x)
        still = np.zeros_like(x)
        forces(self.kernel, x, y, still, still, np.ones_like(x), fx, fy)
        return np.column_stack([fx, fy])

    def accelerations(self, x, y, u, w) -> np.ndarray:
        """(n_bodies, 2) accelerations at the displacements (x, y) and velocities (u, w)."""
        ax, ay = np.zeros_like(x), np.zeros_like(x)
        forces(self.kernel, x, y, u, w, self.kernel.inv_mass, ax, ay)
        return np.column_stack([ax, ay])

    def integrate(self, velocities, dt: float, settings: RunSettings, emit):
        """RK4 from rest positions with ``velocities`` (in ``units``); ``emit(index, step, x, y, u, w)``
        at step 0 and every ``settings.dump_every`` steps, with the displacements (x, y) and
        velocities (u, w)."""
        x, y = np.zeros(len(velocities)), np.zeros(len(velocities))
        u, w = (np.array(column, float) for column in np.asarray(velocities, float).T)
        every = settings.dump_every
        emit(0, 0, x, y, u, w)
        for index in range(1, settings.n_samples):
            self.pairs.advance(every, lambda kernel, n: integrate(kernel, x, y, u, w, float(dt), n), x, y)
            emit(index, index * every, x, y, u, w)


def _check_settings(settings: RunSettings) -> None:
    if not (is_number(settings.dt_s) and settings.dt_s > 0):
        raise HexdemError(f"time step must be a positive number of seconds, got {settings.dt_s!r}")
    for name in ("n_steps", "dump_every"):
        positive_int(name, getattr(settings, name))


@dataclass(frozen=True)
class ReferenceEngine:
    """The reference integrator as a hexdem engine (same protocol as ``LammpsEngine``; one rank)."""

    name = "reference"

    def run(
        self,
        model: GranularModel,
        settings: RunSettings,
        directory,
        on_sample: Observer,
        comm=None,
        show_progress: bool = True,
    ) -> dict:
        """Integrate ``model`` with ``settings``, calling ``on_sample`` with every sample; write
        ``reference.json`` into ``directory``. Returns a description of the run."""
        _check_settings(settings)
        if comm is not None and comm.Get_size() > 1:
            raise HexdemError("the reference integrator runs on one rank; use ranks = 1 with it")
        units = settings.units
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        system = (FrictionalSystem if model.laws.tangential else ReferenceSystem).from_model(model, units)
        start_positions = model.initial_positions_m() / units.length_m
        ids = np.arange(1, model.n_bodies + 1)
        dt = settings.dt_s / units.time_s
        bar = progress_bar(settings.n_steps, "reference", unit="step") if show_progress else None

        def emit(index, step, x, y, u, w):
            velocities = np.column_stack([u, w])
            sensed = settings.sensor_every and step % settings.sensor_every == 0
            accelerations = system.accelerations(x, y, u, w) if sensed else None
            if not (np.isfinite(velocities).all() and np.isfinite(x).all() and np.isfinite(y).all()):
                raise HexdemError(
                    f"reference integration diverged (non-finite state at t = "
                    f"{step * settings.dt_s:.4g} s): reduce the time step"
                )
            on_sample(
                Sample(
                    index,
                    step,
                    step * dt,
                    ids,
                    start_positions + np.column_stack([x, y]),
                    velocities,
                    accelerations,
                    system.angular_velocities(),
                )
            )
            if bar is not None:
                bar.update(step - bar.n)

        n_pairs = system.pairs.n_pairs
        begin = time.perf_counter()
        try:
            system.integrate(model.initial_velocities_m_s() / units.velocity_m_s, dt, settings, emit)
        finally:
            if bar is not None:
                bar.close()
        engine = {
            "name": self.name,
            "version": version("hexdem"),
            "ranks": 1,
            "integrator": "classical RK4",
            "friction": model.laws.tangential,
            "units": units.name,
            "wall_time_s": time.perf_counter() - begin,
            "n_pairs": n_pairs,
            "n_list_builds": system.pairs.builds,
            "skin": system.pairs.skin,
            "n_wall_contacts": system.n_wall_contacts,
        }
        write_json(
            directory / PARAMETERS_NAME,
            {
                **engine,
                "model": model.packing.shape,
                "n_bodies": model.n_bodies,
                "time_step": dt,
                "n_steps": settings.n_steps,
                "dump_every": settings.dump_every,
                "unit_scales_si": {"length_m": units.length_m, "mass_kg": units.mass_kg, "time_s": units.time_s},
            },
        )
        return engine
