"""``shape = "random"``: a disordered polydisperse disc, packed by LAMMPS, then struck as a
packing of measured positions.

The beads and their loose start come from :mod:`hexdem.model.random_disc`. Two damped settling
decks (:mod:`hexdem.engines.lammps.settling`), the compaction of the disorder ensembles'
preparation (:mod:`hexdem.disorder.preparation`) with a pull towards the centre in place of
pushes on flat edges, pack them:

1. ``compact``: every bead is pulled towards the disc's centre by a constant
   :data:`PULL_FORCE_N` (5 N, the ensembles' push), against a viscous drag of damping time
   1.5 ms, until the kinetic energy is below ½ (Σ m) v_rms², v_rms = 10 µm/s. The time step
   is reset so that no bead moves more than 1 µm a step: the loose beads travel a third of the
   radius, and the contacts they make last some 100 µs.
2. ``relax``: the pull is removed, and a fifteen times stronger drag (damping time 0.1 ms,
   shorter than a contact's) lets the compaction's overlaps (a few µm) relax without flinging
   the beads apart, until the kinetic energy is below the same bound and no net force component
   exceeds 1e-6 N (0.1 µm and at most 2 µs per step): most neighbour pairs are left within 1 µm
   of touching, where a weaker drag lets the released overlaps throw the beads apart (measured:
   docs/validation/benchmarks.md, *Figures moved out of the docstrings*).

The settled centres and diameters are written as ``packing.csv`` (``x,y,diameter``, the
header of a ``packing_file``), and the run goes on as ``shape = "packing"`` of that file,
struck at the middle of the edge facing the strike
(:func:`~hexdem.model.random_disc.edge_bead`), with the configuration's ``walls``. The decks
stay beside it, to be rerun by hand (``lmp -in in.hexdem``).

Before LAMMPS packs it, the run is checked on the loose start (:func:`check_random_run`), so that
``hexdem run``, ``compare`` and ``sweep`` refuse it before anything is written.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from hexdem.common.io import write_csv
from hexdem.engines.lammps.settling import (
    SETTLED_NAME,
    SettlingStage,
    read_data_file,
    read_stage,
    run_settling_deck,
    write_settling_deck,
)
from hexdem.errors import HexdemError, RunFailed
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.packing import strike_direction
from hexdem.model.random_disc import edge_bead, loose_positions, random_diameters
from hexdem.model.run_settings import run_settings

#: The pull towards the centre in the compaction [N per bead].
PULL_FORCE_N = 5.0
#: Radius about the disc's centre within which the pull falls linearly to zero [m]. A constant
#: pull flips across the centre, and a bead that the compaction brings there (the middle bead of
#: a small disc: one of 4, 7 or 10) was shaken at about 1 mm/s for ever, so that the stage never
#: settled. Ten compaction steps' travel (:data:`COMPACT_MAX_STEP_M`), so that no step jumps
#: across it; its stiffness, PULL_FORCE_N / PULL_CORE_M = 5e5 N/m, keeps ω dt at the largest step
#: far below velocity Verlet's limit of 2 (0.11 for a steel bead of 0.85 d). Beads farther out
#: feel the same pull as without it.
PULL_CORE_M = 1e-5
#: Damping times M/γ of the two decks [s].
COMPACT_DAMPING_S = 1.5e-3
RELAX_DAMPING_S = 1e-4
#: Settled: rms bead speed below this [m/s], and (relax) no net force component above this [N].
SETTLED_RMS_SPEED_M_S = 1e-5
SETTLED_MAX_FORCE_N = 1e-6
#: Largest distance a bead moves in one step in each deck [m], and the largest step [s].
COMPACT_MAX_STEP_M = 1e-6
RELAX_MAX_STEP_M = 1e-7
COMPACT_MAX_DT_S = 2e-5
RELAX_MAX_DT_S = 2e-6
#: The packing's file, the decks' folders.
PACKING_NAME = "packing.csv"
STAGES = ("compact", "relax")


def pull_block(force_n: float) -> str:
    """A constant force ``force_n`` [N] on every bead towards the origin, the disc's centre,
    falling linearly to zero within :data:`PULL_CORE_M` of it."""
    core = repr(PULL_CORE_M)
    return (
        "variable        pull_r atom sqrt(x*x+y*y)\n"
        f"variable        pull_reach atom v_pull_r+({core}-v_pull_r)*(v_pull_r<{core})\n"
        f"variable        pull_x atom -{force_n!r}*x/v_pull_reach\n"
        f"variable        pull_y atom -{force_n!r}*y/v_pull_reach\n"
        "fix             pull all addforce v_pull_x v_pull_y 0.0\n"
    )


def settling_stage(name: str) -> SettlingStage:
    """The settling deck of stage ``name`` ("compact" or "relax"; see the module docstring)."""
    compact = name == "compact"
    return SettlingStage(
        name=name,
        purpose='Packing of a random polydisperse disc (shape = "random").',
        walls="# (none)\n",
        loads=pull_block(PULL_FORCE_N) if compact else "# (none)\n",
        loads_note=f"{PULL_FORCE_N:g} N on every bead towards the centre" if compact else "none: the pull is removed",
        damping_s=COMPACT_DAMPING_S if compact else RELAX_DAMPING_S,
        force_tolerance_n=None if compact else SETTLED_MAX_FORCE_N,
        settled_rms_speed_m_s=SETTLED_RMS_SPEED_M_S,
        max_step_m=COMPACT_MAX_STEP_M if compact else RELAX_MAX_STEP_M,
        max_dt_s=COMPACT_MAX_DT_S if compact else RELAX_MAX_DT_S,
        check_every=100,
        min_steps=1000,
        max_steps=2_000_000,
    )


def _packing_config(config: RunConfig, path: Path, struck: int, walls: str) -> RunConfig:
    """``config`` as the ``packing`` of the file at ``path``, its random disc's keys at their defaults."""
    return config.replace(
        shape="packing",
        packing_file=str(path),
        struck_bead=struck,
        walls=walls,
        radius_m=RunConfig.radius_m,
        diameter_spread=RunConfig.diameter_spread,
        seed=RunConfig.seed,
    )


def _write_packing(path: Path, positions_m, diameters_m) -> Path:
    write_csv(path, ("x", "y", "diameter"), np.column_stack([positions_m, diameters_m]).tolist())
    return path


def _loose_start(config: RunConfig, directory: Path) -> tuple[Path, np.ndarray, np.ndarray]:
    """(its file ``loose.csv`` in ``directory``, positions [m], diameters [m]) of the random disc's loose start."""
    diameters = random_diameters(config.radius_m, config.diameter_m, config.diameter_spread, config.seed)
    positions = loose_positions(diameters, config.seed)
    return _write_packing(directory / "loose.csv", positions, diameters), positions, diameters


def _struck(config: RunConfig, positions_m, diameters_m) -> int:
    return edge_bead(positions_m, diameters_m, strike_direction(config.strike_direction_deg))


def check_random_run(config: RunConfig) -> None:
    """Refuse, before LAMMPS packs it, a random disc whose run could not go on: its run is built and
    its time step and sampling set (:func:`~hexdem.model.run_settings.run_settings`) on the loose
    start, whose beads, labels and struck edge are those the packing will have; any other
    configuration passes."""
    if config.shape != "random":
        return
    with tempfile.TemporaryDirectory(prefix="hexdem-loose-") as scratch:
        loose, positions, diameters = _loose_start(config, Path(scratch))
        struck = _packing_config(config, loose, _struck(config, positions, diameters), config.walls)
        run_settings(struck, build_model(struck))


def _kept(deck: Path) -> Path:
    """Move a failed settling ``deck`` out of the run's folder, which a failed run removes, into a
    fresh folder of the system's temporary directory, for inspection."""
    kept = Path(tempfile.mkdtemp(prefix="hexdem-failed-")) / deck.name
    shutil.move(str(deck), kept)
    return kept


def prepare_random_packing(config: RunConfig, directory, log=None) -> RunConfig:
    """Pack ``config``'s random disc in ``directory`` (its decks and ``packing.csv``) and return
    the configuration that strikes it (``shape = "packing"``); any other configuration is
    returned as it is. A run that cannot go on is refused first
    (:func:`check_random_run`); a deck that fails or does not settle is kept outside
    ``directory``, in the folder its message names."""
    if config.shape != "random":
        return config
    check_random_run(config)
    log = log or (lambda message: None)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    loose, _, diameters = _loose_start(config, directory)
    bare = config.replace(
        impacts=(),
        lines=(),
        sensors=(),
        regions=(),
        vacancies=(),
        initial_state_file=None,
        strike_angle_deg=None,
        precompression_n=0.0,
    )
    model = build_model(_packing_config(bare, loose, 0, "none"))
    log(
        f"packing a random disc of {len(diameters)} beads (radius {config.radius_m:g} m, "
        f"diameters d (1 ± {config.diameter_spread:g}), seed {config.seed}) with LAMMPS"
    )
    for number, name in enumerate(STAGES, 1):
        stage, start = settling_stage(name), time.perf_counter()
        log(
            f"random disc, stage {number} of {len(STAGES)}: {name} (loads {stage.loads_note}), until the rms speed "
            f"is below {stage.settled_rms_speed_m_s:g} m/s"
        )
        deck = write_settling_deck(model, stage, directory / name)
        try:
            run_settling_deck(deck)
        except HexdemError as exc:
            raise type(exc)(str(exc).replace(str(deck), str(_kept(deck)))) from None
        result = read_stage(deck)
        log(
            f"random disc, {name}: {'settled' if result.settled else 'stopped'} after {result.steps} steps, "
            f"{result.time_s:.3g} s simulated, in {time.perf_counter() - start:.1f} s"
        )
        if not result.settled:
            raise RunFailed(
                f"the random disc's {name} stage did not settle in {result.steps} steps "
                f"(kinetic energy {result.kinetic_energy_j:.3g} J, largest force "
                f"{result.max_force_n:.3g} N); see {_kept(deck)}"
            )
        state = read_data_file(deck / SETTLED_NAME)
        model = replace(model, packing=model.packing.with_geometry(state.positions_m, state.diameters_m))
    packed = _write_packing(directory / PACKING_NAME, state.positions_m, state.diameters_m)
    struck = _struck(config, state.positions_m, state.diameters_m)
    log(f"random disc packed: {len(diameters)} beads, area fraction {area_fraction(state):.3f}, struck bead {struck}")
    return _packing_config(config, packed, struck, config.walls)


def packing_name(config: RunConfig, lattice) -> str:
    """What the packing ``lattice`` of ``config`` is, for titles: ``random disc of N beads (seed s)``
    for a random disc (built as the packing of its ``packing.csv``), else its builder's name."""
    return f"random disc of {len(lattice)} beads (seed {config.seed})" if config.shape == "random" else lattice.shape


def area_fraction(state) -> float:
    """The beads' area over that of the smallest disc about their centroid that holds them all."""
    centre = state.positions_m.mean(axis=0)
    extent = float(np.max(np.linalg.norm(state.positions_m - centre, axis=1) + state.diameters_m / 2))
    return float(np.sum(state.diameters_m**2)) / 4 / extent**2
