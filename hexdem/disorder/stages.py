"""A disordered packing's preparation in one folder (Sec. VI-A): its two stages, ``compact`` and
``settle``, each a LAMMPS deck in a subfolder of its own, the model each starts from and the
packing they leave. ``hexdem ensemble`` runs each stage of many packings as a task of its own
(:mod:`hexdem.disorder.runner`); a calibration prepares one packing in one task
(:func:`prepare`); both read what the stages left through the functions below.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from hexdem.common.io import atomic_directory
from hexdem.disorder.preparation import Disorder, Preparation, spaced_packing, walls_for_settling, write_stage_deck
from hexdem.engines.lammps.settling import SETTLED_NAME, read_data_file, read_stage
from hexdem.engines.lammps.standalone import run_deck
from hexdem.errors import RunFailed
from hexdem.model.granular import GranularModel
from hexdem.model.packing import Packing


def compaction_model(model: GranularModel, lattice: Packing, diameters_m, disorder: Disorder) -> GranularModel:
    """Stage 1's start: ``model`` on ``lattice`` spaced for the beads' ``diameters_m`` [m]."""
    return replace(model, packing=spaced_packing(lattice, diameters_m, disorder))


def stage_state(directory: Path, what: str, hint: str = ""):
    """The state a stage's deck in ``directory`` settled in; a stage that stopped unsettled is a
    :class:`~hexdem.errors.RunFailed` naming ``what`` was prepared, ending with ``hint``."""
    result = read_stage(directory)
    if not result.settled:
        raise RunFailed(
            f"{what}: stage {directory.name!r} did not settle in {result.steps} steps "
            f"(kinetic energy {result.kinetic_energy_j:.3g} J, tolerance {result.tolerance_j:.3g} J; "
            f"largest force {result.max_force_n:.3g} N, tolerance {result.force_tolerance_n:.3g} N)" + hint
        )
    return read_data_file(directory / SETTLED_NAME)


def settling_model(
    model: GranularModel, lattice: Packing, folder: Path, preparation: Preparation, what: str, hint: str = ""
) -> GranularModel:
    """Stage 2's start: ``lattice`` as ``folder``/compact left it, with the walls of the settling
    (touching it, or stood back by the preparation's slack)."""
    compacted = stage_state(Path(folder) / "compact", what, hint)
    walled = lattice.with_geometry(compacted.positions_m, compacted.diameters_m)
    return replace(model, packing=walls_for_settling(walled, preparation))


def settled_packing(
    model: GranularModel, lattice: Packing, folder: Path, preparation: Preparation, what: str, hint: str = ""
) -> Packing:
    """The packing the preparation in ``folder`` left: settled, with the walls placed after compaction."""
    walled = settling_model(model, lattice, folder, preparation, what, hint).packing
    settled = stage_state(Path(folder) / "settle", what, hint)
    return replace(walled, positions_m=settled.positions_m, diameters_m=settled.diameters_m)


def prepare(model: GranularModel, compaction: GranularModel, preparation: Preparation, folder: Path) -> None:
    """Run both stages of the packing ``compaction`` starts from (:func:`compaction_model`) into
    ``folder``, one after the other in this process; ``folder`` exists only once both settled."""
    folder = Path(folder)
    with atomic_directory(folder) as partial:
        run_deck(write_stage_deck(compaction, "compact", preparation, partial / "compact"))
        settling = settling_model(model, model.packing, partial, preparation, str(folder))
        run_deck(write_stage_deck(settling, "settle", preparation, partial / "settle"))
        stage_state(partial / "settle", str(folder))
